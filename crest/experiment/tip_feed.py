"""Tip samples from the tracker, stamped on the control loop's clock.

The tracker driver stamps samples with the host's monotonic clock; the loop may run on
simulated time. A sample is taken as new when its frame number changes, and is stamped with
the loop time at which it was first seen, so both clocks agree (tracker latency is below one
cycle of the 40 Hz tracker). `age_s` is the loop time since the last valid tip, or, before the
first one, since the first poll: a run whose first frames report the tool MISSING (dropout) has
the same loss_timeout_s of grace as one that loses the tool later.

In simulated time (`sample_period_s` given) the loop runs faster than the wall-clock tracker, so
the feed asks for a fresh frame once per tracker period of simulated time and waits for it:
the samples then describe the simulated catheter at that instant, as a real tracker would. The
first frame to arrive may have been requested before the last cycle (the tracker thread polls
on its own), so the feed waits for the one after it. A busy host may delay a frame by more than
a tracker period of wall time; that is not tracker loss, so the feed keeps waiting while the
driver still reports TRACKING (up to STALLED_TRACKER_TIMEOUT_S). Once the driver reports the
link lost, the poll returns None at once and the simulated age grows.
"""
from __future__ import annotations

import math
import time

import numpy as np

from control import TipMeasurement
from crest.tracker import AuroraDriver, TipSample, TrackerState


FRESH_SAMPLE_WAIT_S = 0.2
"""One wait for a new frame, after which the feed checks the driver's link state."""

STALLED_TRACKER_TIMEOUT_S = 5.0
"""Longest wall-clock wait for one frame while the driver still reports TRACKING."""


class TipFeed:
    def __init__(self, tracker: AuroraDriver | None, sample_period_s: float | None = None):
        self.tracker = tracker
        self.sample_period_s = sample_period_s
        self._next_sample_s = 0.0
        self._frame: int | None = None
        self._silent_since_s: float | None = None    # the last valid tip's time, or the first poll's before any
        self._now_s = 0.0
        self.latest_tip_mm: np.ndarray | None = None

    def poll(self, now_s: float) -> TipMeasurement | None:
        """The newest tip as a measurement, or None (no tracker, no new frame, or tool missing)."""
        self._now_s = now_s
        if self._silent_since_s is None:
            self._silent_since_s = now_s
        if self.tracker is None:
            return None
        if self.sample_period_s is None:
            sample = self.tracker.latest()
        elif now_s + 1e-9 < self._next_sample_s:
            return None
        else:
            self._next_sample_s = now_s + self.sample_period_s
            if self._wait_next() is None:          # possibly requested before now
                return None
            sample = self._wait_next()
        if sample is None or sample.frame == self._frame:
            return None
        self._frame = sample.frame
        if sample.tip_mm is None:
            self.latest_tip_mm = None
            return None
        self.latest_tip_mm = np.asarray(sample.tip_mm, dtype=float)
        self._silent_since_s = now_s
        return TipMeasurement(self.latest_tip_mm, now_s)

    def _wait_next(self) -> TipSample | None:
        """The next frame in wall time; None once the driver reports the link lost (or it stalls)."""
        deadline_s = time.monotonic() + STALLED_TRACKER_TIMEOUT_S
        while True:
            try:
                return self.tracker.wait_next(FRESH_SAMPLE_WAIT_S)
            except TimeoutError:
                if self.tracker.state is not TrackerState.TRACKING or time.monotonic() > deadline_s:
                    return None

    def age_s(self) -> float:
        """Loop time since the last valid tip, or since the first poll before any (inf before that)."""
        return math.inf if self._silent_since_s is None else self._now_s - self._silent_since_s
