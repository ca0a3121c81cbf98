"""How long the drives take to answer a SYNC, as the master sees it.

The latency of a cycle is the wall time from the SYNC sent to the moment the master holds every
drive's TPDO1 answer to it (SyncCycle's wait, its own wake-up included). The master sends the next
SYNC only after that wait and the cycle's own work, so on a served virtual testbed, where an
answer crosses two processes and a WebSocket, this latency is most of the SYNC period; its tail is
what makes a SYNC late (README, "Full stack across the process boundary").

Latencies go into a histogram of BIN_S bins up to LONGEST_BIN_S (the last bin holds everything
longer), so a run of any length keeps a fixed memory; percentiles are read to a bin, the longest
exactly. Cycles in which some drive did not answer in time have no latency and are counted apart.
"""
from __future__ import annotations

import bisect
import itertools

BIN_S = 1e-5
LONGEST_BIN_S = 0.05


class AnswerLatency:
    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        self._counts = [0] * (int(round(LONGEST_BIN_S / BIN_S)) + 1)
        self.answered = 0
        self.unanswered = 0
        self.longest_s = 0.0

    def add(self, latency_s: float) -> None:
        """A cycle whose answers all came, `latency_s` after its SYNC."""
        self._counts[min(int(latency_s / BIN_S), len(self._counts) - 1)] += 1
        self.answered += 1
        self.longest_s = max(self.longest_s, latency_s)

    def add_unanswered(self) -> None:
        """A cycle in which some drive's answer did not come in time."""
        self.unanswered += 1

    def percentile_s(self, percent: float) -> float:
        """The latency below which `percent` % of the answered cycles fall: the upper edge of the bin
        holding that rank (NaN before any answered cycle)."""
        if not self.answered:
            return float("nan")
        rank = max(1, int(round(percent / 100.0 * self.answered)))
        cumulative = list(itertools.accumulate(self._counts))
        return min((bisect.bisect_left(cumulative, rank) + 1) * BIN_S, self.longest_s)

    def summary(self) -> dict:
        """{"answered", "unanswered", "p50_ms", "p99_ms", "p99_9_ms", "longest_ms"}."""
        return {"answered": self.answered, "unanswered": self.unanswered,
                "p50_ms": 1e3 * self.percentile_s(50.0), "p99_ms": 1e3 * self.percentile_s(99.0),
                "p99_9_ms": 1e3 * self.percentile_s(99.9), "longest_ms": 1e3 * self.longest_s}
