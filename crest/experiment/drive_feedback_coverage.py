"""Which rows of a run hold a drive's answer to that row's SYNC, and which repeat an older one.

A row's `tendon_pos_k`, `insertion_pos` and `tendon_force_k` are what each drive reported in its
TPDO1 for that SYNC. When a drive's TPDO1 did not come in time (CycleSample.fresh False for that
axis: a drive falling silent, a frame lost or late), the row still holds numbers, because
`crest-log/1` requires them on every row: the axis' last reported position and force, from an
earlier SYNC. This counts such rows per axis and notes the first one's time (s since the run's
first row), so the log's summary says which rows of which axis are not that SYNC's measurement.
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import Any


class DriveFeedbackCoverage:
    """`add` once per row, in time order, with the row's time (the log's t: s since its first row)
    and each axis' freshness."""

    def __init__(self, axis_names: Sequence[str]):
        self.axis_names = tuple(axis_names)
        self.stale_rows = dict.fromkeys(self.axis_names, 0)
        self.first_stale_s: dict[str, float] = {}

    def add(self, t_s: float, fresh: Sequence[bool]) -> None:
        for name, is_fresh in zip(self.axis_names, fresh):
            if not is_fresh:
                self.stale_rows[name] += 1
                self.first_stale_s.setdefault(name, t_s)

    def summary(self) -> dict[str, Any]:
        """{"rows_with_stale_drive_feedback": {axis: rows}, "first_stale_drive_feedback_s": {axis: t}},
        axes with none left out (both empty when every row held every drive's answer)."""
        return {"rows_with_stale_drive_feedback": {name: n for name, n in self.stale_rows.items() if n},
                "first_stale_drive_feedback_s": dict(self.first_stale_s)}
