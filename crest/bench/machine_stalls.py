"""The machine's own stalls: how late an idle real-time process wakes up, the floor under any cycle.

A virtual machine is paused now and then by its host (steal time, a host's housekeeping), and
every program on it then misses its deadlines at once, whatever its own code does. `cyclictest`
(rt-tests) measures this latency; this probe does the same from Python, so `crest bench` can put
the full stack's missed cycles next to the machine's own stalls, measured on the same machine
just before (`machine_floor`). It runs alone, not beside the stack: a process waking every
millisecond at a priority above the stack's threads would take its own share of their CPUs.

The probe is a process of its own that does nothing but sleep to absolute deadlines every
`period_s`, under SCHED_FIFO at `priority` (nothing of lower priority can run in its way), on one
CPU. Each wake-up later than STALL_THRESHOLD_S is a stall of the machine: the interval [wake -
lateness, wake]. It reads stdin and stops when stdin closes (also when its parent dies), then
prints its report as one JSON line.

    python -m crest.bench.machine_stalls PERIOD_S PRIORITY CPU      (CPU -1: not pinned)

A virtual CPU stalls on its own as well as with the whole machine (on this project's 2-CPU
machine, 2026-11-27: two probes pinned apart for 90 s, twice, saw 1 and 5 stalls on one CPU alone
and 1 on both at once). The full stack uses every CPU (the master on one, the served testbed on
another, crest.testbed_service.cpu_split), and a stall of either delays its SYNC, so its floor is
`machine_floor`: one probe pinned to each CPU, all at once, and the union of their stalls.
"""
from __future__ import annotations

import json
import os
import select
import subprocess
import sys
import time
from contextlib import ExitStack
from dataclasses import dataclass

from crest.driver.realtime_scheduling import realtime_threads

PROBE_PERIOD_S = 0.001
PROBE_PRIORITY = 90                # cyclictest's customary priority, above the bench's 20
STALL_THRESHOLD_S = 0.0005         # a wake-up this late is a stall (the probe itself wakes in ~0.05 ms)
READY = "ready"


@dataclass(frozen=True)
class StallReport:
    """What the probe saw: its scheduling, its wake-ups, each stall (a wake-up more than
    STALL_THRESHOLD_S late) as (start_s, end_s) on time.time()'s clock, and the CPUs it ran on."""

    scheduling: str
    wakeups: int
    stalls: tuple[tuple[float, float], ...]
    cpus: tuple[int, ...] = ()

    @property
    def longest_ms(self) -> float:
        return max((1e3 * (end - start) for start, end in self.stalls), default=0.0)

    def longer_than(self, duration_s: float) -> int:
        """How many stalls lasted longer than `duration_s` (at 500 Hz, a stall over 1 ms delays a
        SYNC past 1.5 periods: a missed cycle, whatever the program)."""
        return sum(end - start > duration_s for start, end in self.stalls)


class MachineStallProbe:
    """The probe process, for a `with` block: `report` holds what it saw once the block ends."""

    def __init__(self, priority: int = PROBE_PRIORITY, period_s: float = PROBE_PERIOD_S, cpu: int | None = None):
        self.priority = priority
        self.period_s = period_s
        self.cpu = cpu
        self.report: StallReport | None = None
        self._process: subprocess.Popen | None = None

    def __enter__(self) -> "MachineStallProbe":
        self._process = subprocess.Popen(
            [sys.executable, "-m", "crest.bench.machine_stalls", repr(self.period_s), str(self.priority),
             str(-1 if self.cpu is None else self.cpu)],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        first = self._process.stdout.readline().strip()
        if first != READY:
            self._process.kill()
            raise RuntimeError(f"the machine stall probe did not start (it said {first!r})")
        return self

    @property
    def pid(self) -> int:
        return self._process.pid

    def __exit__(self, *exc_info) -> None:
        try:
            output, _ = self._process.communicate(input="", timeout=30.0)   # closing stdin stops it
            self.report = parse_report(output)
        finally:
            if self._process.poll() is None:
                self._process.kill()
                self._process.wait()


@dataclass(frozen=True)
class MachineFloor:
    """The stalls of every CPU, probed at the same time: `per_cpu` maps a CPU to its probe's report."""

    per_cpu: dict[int, StallReport]

    @property
    def any_cpu(self) -> StallReport:
        """The union of the CPUs' stalls (overlapping intervals merged into one): what delays a
        program that needs every CPU."""
        merged: list[tuple[float, float]] = []
        for start, end in sorted(s for report in self.per_cpu.values() for s in report.stalls):
            if merged and start <= merged[-1][1]:
                merged[-1] = (merged[-1][0], max(merged[-1][1], end))
            else:
                merged.append((start, end))
        first = next(iter(self.per_cpu.values()))
        return StallReport(first.scheduling, sum(r.wakeups for r in self.per_cpu.values()), tuple(merged),
                           tuple(sorted(cpu for report in self.per_cpu.values() for cpu in report.cpus)))

    def on_every_cpu(self, duration_s: float) -> int:
        """How many stalls longer than `duration_s` overlap a stall of every other CPU: the whole
        machine paused at once."""
        reports = list(self.per_cpu.values())
        return sum(all(any(s < end and start < e for s, e in other.stalls) for other in reports[1:])
                   for start, end in reports[0].stalls if end - start > duration_s)


def machine_floor(duration_s: float, priority: int = PROBE_PRIORITY) -> MachineFloor:
    """One probe pinned to each CPU this process may use, all for the same `duration_s`: the
    stalls of the machine as it is now."""
    cpus = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else [None]
    with ExitStack() as stack:
        probes = {cpu: stack.enter_context(MachineStallProbe(priority, cpu=cpu)) for cpu in cpus}
        time.sleep(duration_s)
    return MachineFloor({(-1 if cpu is None else cpu): probe.report for cpu, probe in probes.items()})


def parse_report(line: str) -> StallReport:
    raw = json.loads(line)
    return StallReport(scheduling=raw["scheduling"], wakeups=int(raw["wakeups"]),
                       stalls=tuple((float(start), float(end)) for start, end in raw["stalls"]),
                       cpus=tuple(int(cpu) for cpu in raw["cpus"]))


def probe(period_s: float, priority: int, cpu: int | None = None) -> dict:
    """Wake every `period_s` on `cpu` (None: wherever the scheduler puts it) until stdin closes;
    the report as a dict (see the module doc).

    The k-th deadline is start + k period (absolute, so a late wake-up does not shift the later
    ones); a wake-up `late` seconds after its deadline records the stall [now - late, now].
    """
    stalls, wakeups = [], 0
    if cpu is not None:
        os.sched_setaffinity(0, {cpu})
    with realtime_threads(priority) as scheduling:
        print(READY, flush=True)
        start = time.monotonic()
        deadline = start + period_s
        while True:
            readable, _, _ = select.select([sys.stdin], [], [], max(0.0, deadline - time.monotonic()))
            if readable and not sys.stdin.readline():
                break                                           # stdin closed: stop
            late_s = time.monotonic() - deadline
            if late_s < 0.0:
                continue                                        # woken early by input; sleep on
            wakeups += 1
            if late_s > STALL_THRESHOLD_S:
                now_s = time.time()
                stalls.append((now_s - late_s, now_s))
            deadline += period_s * (1 + int(late_s // period_s))   # the next deadline still ahead
    return {"scheduling": scheduling.describe(), "wakeups": wakeups, "stalls": stalls,
            "cpus": sorted(os.sched_getaffinity(0))}


if __name__ == "__main__":
    pinned_cpu = int(sys.argv[3])
    print(json.dumps(probe(float(sys.argv[1]), int(sys.argv[2]), None if pinned_cpu < 0 else pinned_cpu)), flush=True)
