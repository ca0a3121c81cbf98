"""How long the drives take to answer a SYNC, as the master sees it.

The latency of a cycle is the wall time from the SYNC sent to the moment the master holds every
drive's TPDO1 answer to it (SyncCycle's wait, its own wake-up included). The master sends the next
SYNC only after that wait and the cycle's own work, so on a served virtual testbed, where an
answer crosses two processes and a WebSocket, this latency is most of the SYNC period; its tail is
what makes a SYNC late (README, "Full stack across the process boundary").

Latencies are kept in a fixed-memory histogram (wall_time_histogram). Cycles in which some drive
did not answer in time have no latency and are counted apart.
"""
from __future__ import annotations

from crest.driver.wall_time_histogram import WallTimeHistogram


class AnswerLatency:
    def __init__(self) -> None:
        self._latencies = WallTimeHistogram()
        self.unanswered = 0

    def reset(self) -> None:
        self._latencies.reset()
        self.unanswered = 0

    @property
    def answered(self) -> int:
        return self._latencies.count

    @property
    def longest_s(self) -> float:
        return self._latencies.longest_s

    def add(self, latency_s: float) -> None:
        """A cycle whose answers all came, `latency_s` after its SYNC."""
        self._latencies.add(latency_s)

    def add_unanswered(self) -> None:
        """A cycle in which some drive's answer did not come in time."""
        self.unanswered += 1

    def percentile_s(self, percent: float) -> float:
        """The latency below which `percent` % of the answered cycles fall (NaN before any)."""
        return self._latencies.percentile_s(percent)

    def summary(self) -> dict:
        """{"answered", "unanswered", "p50_ms", "p99_ms", "p99_9_ms", "longest_ms"}."""
        return {"answered": self.answered, "unanswered": self.unanswered,
                "p50_ms": 1e3 * self.percentile_s(50.0), "p99_ms": 1e3 * self.percentile_s(99.0),
                "p99_9_ms": 1e3 * self.percentile_s(99.9), "longest_ms": 1e3 * self.longest_s}
