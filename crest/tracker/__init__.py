"""The NDI Aurora tip tracker: reply parsing and the polling driver."""

from crest.tracker.aurora_driver import AuroraDriver, TipSample, TrackerLinkError, TrackerState, TrackerStats
from crest.tracker.aurora_reply import TrackerCrcError, TrackerErrorReply, TrackerProtocolError

__all__ = ["AuroraDriver", "TipSample", "TrackerCrcError", "TrackerErrorReply", "TrackerLinkError",
           "TrackerProtocolError", "TrackerState", "TrackerStats"]
