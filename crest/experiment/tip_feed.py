"""Tip samples from the tracker, stamped on the control loop's clock.

The tracker driver stamps samples with the host's monotonic clock; the loop may run on
simulated time. A sample is new when its frame number differs from the last one taken, and is
stamped with the loop time at which it was first seen, so both clocks agree (tracker latency is
below one cycle of the 40 Hz tracker). `poll` returns a measurement only for a new frame with the
tool in view: a loop faster than the tracker gets None between frames, and a log row written from
it has an empty tip, never the previous frame's tip again. `age_s` is the loop time since the
last valid tip, or, before the first one, since the first poll: a run whose first frames report
the tool MISSING (dropout) has the same loss_timeout_s of grace as one that loses the tool later.

In simulated time (`sample_period_s` given) the loop runs faster than the wall-clock tracker, so
the feed asks for a fresh frame once per tracker period of simulated time and waits for it
(`AuroraDriver.fresh_sample`: a frame whose TX was sent after the request; the session runs the
driver on demand, so it sends no other TX): the samples then describe the simulated catheter at
that instant, as a real tracker would. The requests keep their phase (at k * sample_period_s), so
a 40 Hz tracker gives 40 samples per simulated second whatever the SYNC period. A busy host may
delay a frame by more than a tracker period of wall time; that is not tracker loss, so the feed
keeps waiting while the driver still reports TRACKING (up to
STALLED_TRACKER_TIMEOUT_S). A busy host may even delay a reply past the driver's reply timeout,
and the driver then reconnects within a fraction of a second: so the first time the feed finds
the link down it waits up to RECONNECT_GRACE_S of wall time for the driver to be TRACKING again,
which costs no simulated time. A link still down after that is lost: until the driver reports
TRACKING again every poll returns None without waiting, so a run that lost its tracker goes on
at simulated speed and the simulated age grows.
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

RECONNECT_GRACE_S = 2.0
"""Longest wall-clock wait, once per loss of the link, for the driver to reconnect (about 0.1 s
of backoff and 0.3 s of set-up on the simulated tracker)."""


class TipFeed:
    """New tracker frames, one `poll` per loop cycle.

    frames: new frames taken so far (with or without a tip).
    latest_tip_mm: the last tip seen (None after a frame with the tool missing), for display; a
    log row takes the tip of `poll`'s measurement, which is None when no new frame arrived.
    """

    def __init__(self, tracker: AuroraDriver | None, sample_period_s: float | None = None):
        self.tracker = tracker
        self.sample_period_s = sample_period_s
        self._next_sample_s: float | None = None
        self._frame: int | None = None
        self._waited_for_link = False              # the grace wait of the current link loss is spent
        self._silent_since_s: float | None = None    # the last valid tip's time, or the first poll's before any
        self._now_s = 0.0
        self.frames = 0
        self.latest_tip_mm: np.ndarray | None = None

    def poll(self, now_s: float) -> TipMeasurement | None:
        """The tip of a frame new since the last poll, or None (no tracker, no new frame, or tool missing)."""
        self._now_s = now_s
        if self._silent_since_s is None:
            self._silent_since_s = now_s
        if self.tracker is None:
            return None
        if self.sample_period_s is None:
            sample = self.tracker.latest()
        elif not self._sample_due(now_s):
            return None
        else:
            sample = self._fresh_sample()
        if sample is None or sample.frame == self._frame:
            return None
        self._frame = sample.frame
        self.frames += 1
        if sample.tip_mm is None:
            self.latest_tip_mm = None
            return None
        self.latest_tip_mm = np.asarray(sample.tip_mm, dtype=float)
        self._silent_since_s = now_s
        return TipMeasurement(self.latest_tip_mm, now_s)

    def _sample_due(self, now_s: float) -> bool:
        """Simulated time: whether a tracker period has passed since the last request.

        Requests fall at t0 + k * sample_period_s (the next one after now_s when the loop fell
        behind), so the mean rate is the tracker's even when the SYNC period does not divide it.
        """
        if self._next_sample_s is not None and now_s + 1e-9 < self._next_sample_s:
            return False
        if self._next_sample_s is None:
            self._next_sample_s = now_s
        missed = math.floor((now_s + 1e-9 - self._next_sample_s) / self.sample_period_s)
        self._next_sample_s += (missed + 1) * self.sample_period_s
        return True

    def _fresh_sample(self) -> TipSample | None:
        """A frame requested now; None when the link is lost (see _link_up) or the frame stalls."""
        deadline_s = time.monotonic() + STALLED_TRACKER_TIMEOUT_S
        while self._link_up():
            try:
                return self.tracker.fresh_sample(FRESH_SAMPLE_WAIT_S)
            except TimeoutError:
                if time.monotonic() > deadline_s:
                    return None
        return None

    def _link_up(self) -> bool:
        """Whether the driver reports TRACKING: the first time it does not, after waiting up to
        RECONNECT_GRACE_S for it to reconnect; from then on at once, until it is back."""
        if self.tracker.state is TrackerState.TRACKING:
            self._waited_for_link = False
            return True
        if self._waited_for_link:
            return False
        self._waited_for_link = True
        return self.tracker.wait_state(TrackerState.TRACKING, RECONNECT_GRACE_S)

    def age_s(self) -> float:
        """Loop time since the last valid tip, or since the first poll before any (inf before that)."""
        return math.inf if self._silent_since_s is None else self._now_s - self._silent_since_s
