"""The machine stall probe (crest.bench.machine_stalls): an idle process that records when it woke
up late, so `crest bench` can tell the machine's own stalls from the stack's."""
import os
import signal
import time

import pytest

from crest.bench.machine_stalls import MachineFloor, MachineStallProbe, StallReport, machine_floor


def test_the_probe_in_another_process_records_a_pause_of_that_process_as_a_stall():
    """SIGSTOP freezes the probe's process as a host freezes a virtual machine: on SIGCONT it wakes
    late, and the stall it records spans the pause."""
    with MachineStallProbe(priority=0) as probe:
        time.sleep(0.3)
        paused_s = time.time()
        os.kill(probe.pid, signal.SIGSTOP)
        time.sleep(0.25)
        os.kill(probe.pid, signal.SIGCONT)
        resumed_s = time.time()
        time.sleep(0.3)
    report = probe.report
    assert report.scheduling == "normal scheduler" and report.wakeups > 100
    pause = [(start, end) for start, end in report.stalls if end - start > 0.2]
    assert len(pause) == 1
    start, end = pause[0]
    assert paused_s - 0.01 < start < paused_s + 0.05 and resumed_s - 0.05 < end < resumed_s + 0.5
    assert report.longer_than(0.2) == 1 and report.longest_ms > 200.0


def test_stalls_are_counted_by_their_length():
    report = StallReport("real-time (SCHED_FIFO, priority 90)", 1000, ((10.000, 10.008), (20.0, 20.0007)))
    assert report.longer_than(0.001) == 1 and report.longer_than(0.0005) == 2
    assert report.longest_ms == pytest.approx(8.0)


def test_the_floor_of_several_cpus_is_the_union_of_their_stalls():
    """A stall of either CPU delays a program that needs both; stalls that overlap count once, and
    only those overlapping on every CPU are the whole machine paused."""
    cpu0 = StallReport("p", 1000, ((10.000, 10.008), (20.0, 20.002)))
    cpu1 = StallReport("p", 1000, ((10.004, 10.010), (30.0, 30.0015)))
    floor = MachineFloor({0: cpu0, 1: cpu1})
    assert floor.any_cpu.stalls == ((10.000, 10.010), (20.0, 20.002), (30.0, 30.0015))
    assert floor.any_cpu.longer_than(0.001) == 3 and floor.any_cpu.longest_ms == pytest.approx(10.0)
    assert floor.on_every_cpu(0.001) == 1


def test_the_floor_probes_every_cpu_from_processes_pinned_to_each():
    """machine_floor starts one probe process per CPU this process may use, each pinned to its CPU."""
    floor = machine_floor(0.3, priority=0)
    assert sorted(floor.per_cpu) == sorted(os.sched_getaffinity(0))
    assert all(report.wakeups > 50 and report.cpus == (cpu,) for cpu, report in floor.per_cpu.items())
