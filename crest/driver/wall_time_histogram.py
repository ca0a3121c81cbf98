"""A fixed-memory histogram of wall-time durations, for timing statistics kept over a whole run.

Durations go into bins of BIN_S up to LONGEST_BIN_S (the last bin holds everything longer), so a
run of any length keeps a fixed memory; a percentile is read to a bin (the upper edge of the bin
holding that rank, never above the longest), the longest exactly.
"""
from __future__ import annotations

import bisect
import itertools

BIN_S = 1e-5
LONGEST_BIN_S = 0.05


class WallTimeHistogram:
    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        self._counts = [0] * (int(round(LONGEST_BIN_S / BIN_S)) + 1)
        self.count = 0
        self.longest_s = 0.0

    def add(self, duration_s: float) -> None:
        self._counts[min(int(duration_s / BIN_S), len(self._counts) - 1)] += 1
        self.count += 1
        self.longest_s = max(self.longest_s, duration_s)

    def percentile_s(self, percent: float) -> float:
        """The duration below which `percent` % of those added fall (NaN before any)."""
        if not self.count:
            return float("nan")
        rank = max(1, int(round(percent / 100.0 * self.count)))
        cumulative = list(itertools.accumulate(self._counts))
        return min((bisect.bisect_left(cumulative, rank) + 1) * BIN_S, self.longest_s)
