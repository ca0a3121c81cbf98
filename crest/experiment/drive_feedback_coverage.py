"""Which rows of a run hold a drive's answer to that row's SYNC, and which hold none.

A row's `tendon_pos_k`, `insertion_pos` and `tendon_force_k` are what each drive reported in its
TPDO1 for that SYNC. When a drive's TPDO1 did not come in time (CycleSample.fresh False for that
axis: a drive falling silent, a frame lost or late), the row's position cell of that axis is
empty, and for a tendon its force cell too (recorder.measured_answers; `crest-log/1` allows
these empty cells): the log never repeats an earlier answer as this SYNC's. This counts such rows
per axis and notes the first one's time (s since the run's first row), so the log's summary says
how many rows of which axis lack that SYNC's measurement; the rows themselves are the ones whose
cells are empty.
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import Any


class DriveFeedbackCoverage:
    """`add` once per row, in time order, with the row's time (the log's t: s since its first row)
    and each axis' freshness."""

    def __init__(self, axis_names: Sequence[str]):
        self.axis_names = tuple(axis_names)
        self.unanswered_rows = dict.fromkeys(self.axis_names, 0)
        self.first_unanswered_s: dict[str, float] = {}

    def add(self, t_s: float, fresh: Sequence[bool]) -> None:
        for name, is_fresh in zip(self.axis_names, fresh):
            if not is_fresh:
                self.unanswered_rows[name] += 1
                self.first_unanswered_s.setdefault(name, t_s)

    def summary(self) -> dict[str, Any]:
        """{"rows_without_drive_answer": {axis: rows}, "first_row_without_drive_answer_s": {axis: t}},
        axes with none left out (both empty when every row held every drive's answer)."""
        return {"rows_without_drive_answer": {name: n for name, n in self.unanswered_rows.items() if n},
                "first_row_without_drive_answer_s": dict(self.first_unanswered_s)}
