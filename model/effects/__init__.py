"""Candidate unmodelled effects: a common interface and the catalog under canonical ids."""
from model.effects.candidate_effect import CandidateEffect
from model.effects.catalog import EFFECTS, combined_terms, effect

__all__ = ["CandidateEffect", "EFFECTS", "combined_terms", "effect"]
