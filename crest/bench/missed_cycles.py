"""Which missed SYNC cycles the machine's own stalls explain, and which are the stack's.

With SYNC times t_0 < t_1 < ... on the bus and the nominal period T, the i-th period
p_i = t_i - t_{i-1} is a missed cycle when p_i > 1.5 T: its SYNC is late by L_i = p_i - T > T/2.

A stall of the machine [a, b] (a probe above every thread of the stack could not run: the host held
the CPU) holds up whatever is due inside it. Within period i it takes
o = min(b, t_i) - max(a, t_{i-1}) when positive; the stalls of every CPU are merged first, so time
in which two CPUs stall together counts once, and O_i is the sum of the merged overlaps. A missed
cycle is the machine's when its SYNC would have been in time had the machine not stalled,
L_i - O_i <= T/2, and the stack's otherwise: late by more than the machine took from it.

The probe's stall is its own wake-up's lateness, a lower bound on the machine's pause (the pause
may have begun up to one probe period before the deadline it overran), so a miss is put down to
the machine only for time the probe saw lost.
"""
from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

LATE_FRACTION = 0.5     # a SYNC later than this share of a period is a missed cycle (p > 1.5 T)


@dataclass(frozen=True)
class MissedCycles:
    """The missed cycles of a run, split by cause (see the module doc); `stack_late_ms` is, for
    each of the stack's own misses, how late its SYNC was less the machine's stall time in it."""

    total: int
    in_machine_stalls: int
    by_the_stack: int
    stack_late_ms: tuple[float, ...]


def merged(intervals: Iterable[tuple[float, float]]) -> list[tuple[float, float]]:
    """The union of closed intervals [a, b] as disjoint intervals, in order."""
    out: list[list[float]] = []
    for start, end in sorted(intervals):
        if out and start <= out[-1][1]:
            out[-1][1] = max(out[-1][1], end)
        else:
            out.append([start, end])
    return [(start, end) for start, end in out]


def attribute_missed_cycles(sync_times_s: Sequence[float], period_s: float,
                            stalls_s: Iterable[tuple[float, float]]) -> MissedCycles:
    """Split the missed cycles between the machine's stalls and the stack (module doc).

    sync_times_s: the SYNCs' time stamps on the bus (time.time() clock, as the probes' stalls).
    stalls_s: the stalls of every probe, (start_s, end_s), in any order, overlapping or not.
    """
    times = np.asarray(sync_times_s, dtype=float)
    late_s = np.diff(times) - period_s
    stalls = merged(stalls_s)
    starts = np.array([start for start, _ in stalls], dtype=float)
    ends = np.array([end for _, end in stalls], dtype=float)
    in_stalls, stack_late_ms = 0, []
    for i in np.flatnonzero(late_s > LATE_FRACTION * period_s):
        begin, end = times[i], times[i + 1]
        overlap_s = float(np.sum(np.clip(np.minimum(ends, end) - np.maximum(starts, begin), 0.0, None)))
        if late_s[i] - overlap_s <= LATE_FRACTION * period_s:
            in_stalls += 1
        else:
            stack_late_ms.append(1e3 * (late_s[i] - overlap_s))
    total = in_stalls + len(stack_late_ms)
    return MissedCycles(total=total, in_machine_stalls=in_stalls, by_the_stack=len(stack_late_ms),
                        stack_late_ms=tuple(stack_late_ms))
