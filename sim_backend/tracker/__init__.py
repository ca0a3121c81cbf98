"""Simulated NDI Aurora tip tracker on a pseudo-terminal."""

from sim_backend.tracker.sim_tracker import SimTracker, TrackerFault

__all__ = ["SimTracker", "TrackerFault"]
