"""Which rows of a run carry a tracker tip, and whether (and when) the tracker was lost.

A row carries a tip only when a new tracker frame with the tool in view arrived since the row
before (tip_feed), so with a 40 Hz tracker and a 100 Hz SYNC about 40% of the rows carry one.
The tracker counts as lost when no tip arrives for longer than loss_timeout_s ([tracker] in the
testbed config, the limit a closed-loop run stops at):

    lost_at_s = t of the last row with a tip before the first such silence
                (the first row's t when no tip came before it),

with t in s since the run's first row (the log's t column). The rows after lost_at_s, and how
many of them carry a tip (a tracker that reconnects gives tips again), are counted too: they go
in the log's summary and in the run's summary line.
"""
from __future__ import annotations

from typing import Any


class TipCoverage:
    """Counts rows with and without a tip; `add` once per row, in time order.

    loss_timeout_s None: the session has no tracker, so no tip is expected and none is lost.
    """

    def __init__(self, loss_timeout_s: float | None):
        self.loss_timeout_s = loss_timeout_s
        self.rows = 0
        self.rows_with_tip = 0
        self.lost_at_s: float | None = None
        self.rows_after_loss = 0
        self.rows_with_tip_after_loss = 0
        self._t0_s: float | None = None
        self._silent_since_s = 0.0        # the last tip's t, or the first row's before any
        self._rows_silent = 0             # rows after _silent_since_s

    def add(self, t_s: float, has_tip: bool) -> None:
        """One row at loop time t_s (s, any origin: times are taken from the first row's)."""
        if self._t0_s is None:
            self._t0_s = t_s
        t_s -= self._t0_s
        self.rows += 1
        self.rows_with_tip += has_tip
        if self.lost_at_s is not None:
            self.rows_after_loss += 1
            self.rows_with_tip_after_loss += has_tip
        elif has_tip:
            self._silent_since_s, self._rows_silent = t_s, 0
        else:
            self._rows_silent += t_s > self._silent_since_s
            if self.loss_timeout_s is not None and t_s - self._silent_since_s > self.loss_timeout_s:
                self.lost_at_s = self._silent_since_s
                self.rows_after_loss = self._rows_silent

    def summary(self) -> dict[str, Any]:
        """The log summary's keys: rows with and without a tip, and the loss (None when not lost)."""
        lost = self.lost_at_s is not None
        return {"rows_with_tip": self.rows_with_tip, "rows_without_tip": self.rows - self.rows_with_tip,
                "tracker_lost_at_s": self.lost_at_s,
                "rows_after_tracker_loss": self.rows_after_loss if lost else None,
                "rows_with_tip_after_tracker_loss": self.rows_with_tip_after_loss if lost else None}

    def loss_sentence(self) -> str | None:
        """E.g. "tracker lost at 1.49 s; 0 of 484 rows after it have a tip", or None when not lost."""
        if self.lost_at_s is None:
            return None
        return (f"tracker lost at {self.lost_at_s:.2f} s; {self.rows_with_tip_after_loss} of "
                f"{self.rows_after_loss} rows after it have a tip")
