"""The hypervisor's steal time per CPU (crest.bench.steal_time), read from the kernel's /proc/stat."""
import os

from crest.bench.steal_time import StealMeter, steal_ticks


def test_every_cpu_has_a_steal_counter_that_never_runs_backwards():
    before = steal_ticks()
    assert os.sched_getaffinity(0) <= set(before)           # every CPU this process may run on
    after = steal_ticks()
    assert all(after[cpu] >= ticks >= 0 for cpu, ticks in before.items())


def test_a_span_gives_each_cpus_steal_in_ms_to_one_tick():
    meter = StealMeter()
    meter.start()
    stolen = meter.stop()
    assert stolen["resolution_ms"] == round(1e3 / os.sysconf("SC_CLK_TCK"), 1)
    assert os.sched_getaffinity(0) <= set(stolen["steal_ms_per_cpu"])
    assert all(ms >= 0.0 and ms % stolen["resolution_ms"] == 0.0 for ms in stolen["steal_ms_per_cpu"].values())
