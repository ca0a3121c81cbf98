"""The CPU time the hypervisor took from each virtual CPU over a span: its steal time.

On a virtual machine the host runs other work on the physical CPU now and then, and the guest's
virtual CPU stands still meanwhile: every thread on it, real-time or not, stalls. The guest's
kernel counts that time per CPU (the 8th field of each ``cpuN`` line of /proc/stat, in ticks of
1/``SC_CLK_TCK`` s, 10 ms here). `crest bench` reads it before and after the full stack runs, so a
missed cycle can be put next to the time the machine itself was not there. The counter is kept in
nanoseconds and shown in whole ticks, so a span's steal is known to one tick: a single stall of a
few milliseconds shows as 0 or 1 tick.
"""
from __future__ import annotations

import os
from pathlib import Path

PROC_STAT = Path("/proc/stat")
STEAL_FIELD = 8     # cpuN user nice system idle iowait irq softirq steal ...


def steal_ticks() -> dict[int, int]:
    """Steal time so far, per CPU number, in ticks ({} where the kernel does not count it)."""
    ticks = {}
    for line in PROC_STAT.read_text().splitlines():
        fields = line.split()
        if fields and fields[0].startswith("cpu") and fields[0] != "cpu" and len(fields) > STEAL_FIELD:
            ticks[int(fields[0][3:])] = int(fields[STEAL_FIELD])
    return ticks


class StealMeter:
    """Steal time per CPU between `start` and `stop`."""

    tick_s = 1.0 / os.sysconf("SC_CLK_TCK")

    def __init__(self) -> None:
        self._before: dict[int, int] = {}

    def start(self) -> None:
        self._before = steal_ticks()

    def stop(self) -> dict:
        """{"steal_ms_per_cpu": {cpu: ms}, "resolution_ms": one tick}; the CPUs counted at both ends."""
        after = steal_ticks()
        return {"steal_ms_per_cpu": {cpu: round((after[cpu] - before) * self.tick_s * 1e3, 1)
                                     for cpu, before in self._before.items() if cpu in after},
                "resolution_ms": round(self.tick_s * 1e3, 1)}
