"""When the master's SYNCs left, as the master itself times them: the achieved rate, the period
jitter and the missed cycles of a run, without a second handle on the bus.

Each SYNC is stamped (wall time, monotonic) as soon as the transport has taken it. With t_k the
k-th stamp since the last reset and T the nominal period:

    period       p_k = t_k - t_(k-1)
    jitter       j_k = |p_k - T|                 (kept in a fixed-memory histogram)
    missed       p_k > MISSED_PERIODS * T        (a SYNC left half a period or more late)
    rate         (K - 1) / (t_K - t_1)           over the K stamps

Each missed cycle is also counted by where its time went, from whether the cycle was ready for
its SYNC (waiting for the due time) before that time came:
    woke late    ready in time: the cycle's thread slept until the SYNC was due and ran again
                 too late (its CPU stalled, or another thread had the CPU or the interpreter lock);
    overran      not ready in time: the cycle before it (the drives' answers, the controller's and
                 the supervisor's work) ran past the due time.

On a served virtual testbed these are the times the SYNCs entered the WebSocket; the drives see
them later by the transport's latency, which the drives' answer latency (answer_latency) covers.
A second client on the bus that stamped the SYNCs where the drives get them would double the
testbed's sending (each frame to two clients) and add a receive thread to the master, both in the
way of the cycle being measured (README, "Full stack across the process boundary").
"""
from __future__ import annotations

from crest.driver.wall_time_histogram import WallTimeHistogram

MISSED_PERIODS = 1.5


class SyncTiming:
    def __init__(self, period_s: float) -> None:
        self.period_s = period_s
        self._jitter = WallTimeHistogram()
        self.reset()

    def reset(self) -> None:
        self._jitter.reset()
        self.syncs = 0
        self.missed = 0
        self.missed_woke_late = 0
        self.longest_period_s = 0.0
        self._first_s: float | None = None
        self._last_s: float | None = None

    def sent(self, now_s: float, ready_in_time: bool = False) -> None:
        """A SYNC left at `now_s` (time.monotonic()); ready_in_time: its cycle was waiting for it
        before it was due (module doc)."""
        if self._last_s is not None:
            period_s = now_s - self._last_s
            self._jitter.add(abs(period_s - self.period_s))
            missed = period_s > MISSED_PERIODS * self.period_s
            self.missed += missed
            self.missed_woke_late += missed and ready_in_time
            self.longest_period_s = max(self.longest_period_s, period_s)
        else:
            self._first_s = now_s
        self._last_s = now_s
        self.syncs += 1

    def summary(self) -> dict:
        """{"syncs", "periods", "span_s", "achieved_rate_hz", "jitter_p50_ms", "jitter_p99_ms",
        "missed_cycles", "missed_woke_late", "missed_overran", "longest_period_ms"} since the last
        reset (rate and jitter NaN before two SYNCs)."""
        span_s = (self._last_s - self._first_s) if self.syncs >= 2 else 0.0
        return {"syncs": self.syncs, "periods": max(self.syncs - 1, 0), "span_s": span_s,
                "achieved_rate_hz": (self.syncs - 1) / span_s if span_s > 0 else float("nan"),
                "jitter_p50_ms": 1e3 * self._jitter.percentile_s(50.0),
                "jitter_p99_ms": 1e3 * self._jitter.percentile_s(99.0),
                "missed_cycles": self.missed, "missed_woke_late": self.missed_woke_late,
                "missed_overran": self.missed - self.missed_woke_late,
                "longest_period_ms": 1e3 * self.longest_period_s}
