"""Reproduction of the seed paper's simulation studies (Figs. 3.1-4.4) with our catheter model."""
from crest.paper.reproduce import SUMMARY, reproduce
from crest.paper.settings import PaperSettings

__all__ = ["SUMMARY", "PaperSettings", "reproduce"]
