"""[sync] realtime_priority, seen from outside: the scheduling policy of every thread of a served
testbed and of a real-time `crest run` joined to it, read from the kernel. Where the system does
not grant the priority, both still run, say why, and stay under the normal scheduler.
"""
import ctypes
import os
import resource
import subprocess
import sys

import pytest

from served_testbed import crest_lines, relaxed_config, start_circle, start_run, start_served_testbed, stop

PRIORITY = 10
PR_CAPBSET_DROP = 24        # linux/prctl.h
CAP_SYS_NICE = 23           # linux/capability.h
CAP_SETPCAP = 8


def thread_policies(pid: int) -> set[tuple[int, int]]:
    """(policy, priority) of every thread of process `pid`."""
    policies = set()
    for thread in os.listdir(f"/proc/{pid}/task"):
        try:
            policies.add((os.sched_getscheduler(int(thread)), os.sched_getparam(int(thread)).sched_priority))
        except ProcessLookupError:
            pass    # ended meanwhile
    return policies


def without_realtime_privilege() -> None:
    """In the child before exec: no rtprio limit and, for root, no CAP_SYS_NICE after exec."""
    resource.setrlimit(resource.RLIMIT_RTPRIO, (0, 0))
    if os.geteuid() == 0:
        if ctypes.CDLL(None, use_errno=True).prctl(PR_CAPBSET_DROP, CAP_SYS_NICE, 0, 0, 0) != 0:
            raise OSError(ctypes.get_errno(), "prctl(PR_CAPBSET_DROP, CAP_SYS_NICE)")


def has_capability(capability: int) -> bool:
    """Whether this process's effective capability set holds `capability` (/proc/self/status CapEff)."""
    with open("/proc/self/status") as status:
        effective = next(int(line.split()[1], 16) for line in status if line.startswith("CapEff:"))
    return bool(effective >> capability & 1)


def realtime_permitted() -> bool:
    probe = [sys.executable, "-c", f"import os; os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param({PRIORITY}))"]
    return subprocess.run(probe, capture_output=True).returncode == 0


@pytest.mark.skipif(not realtime_permitted(), reason="this user may not use SCHED_FIFO (no CAP_SYS_NICE, ulimit -r 0)")
def test_a_served_testbed_and_a_run_joined_to_it_run_every_thread_at_the_configured_priority(tmp_path):
    served = start_served_testbed(tmp_path / "served",
                                  relaxed_config(tmp_path / "config", realtime_priority=PRIORITY))
    try:
        expected = f"real-time (SCHED_FIFO, priority {PRIORITY})"
        assert served.state["scheduling"] == expected
        assert thread_policies(served.state["pid"]) == {(os.SCHED_FIFO, PRIORITY)}
        run = start_run(served, tmp_path / "run.csv")
        try:
            assert thread_policies(run.pid) == {(os.SCHED_FIFO, PRIORITY)}
        finally:
            stop(run)
        assert not [line for line in crest_lines(run.communicate()[1]) if "not permitted" in line]
    finally:
        stop(served.process)
    assert f"threads:    {expected}" in served.process.communicate()[0]


@pytest.mark.skipif(os.geteuid() == 0 and has_capability(CAP_SYS_NICE) and not has_capability(CAP_SETPCAP),
                    reason="root with CAP_SYS_NICE but without CAP_SETPCAP cannot drop the privilege for the test")
def test_without_the_privilege_both_processes_say_why_and_run_under_the_normal_scheduler(tmp_path):
    served = start_served_testbed(tmp_path / "served",
                                  relaxed_config(tmp_path / "config", realtime_priority=PRIORITY),
                                  preexec_fn=without_realtime_privilege)
    refusal = f"real-time priority {PRIORITY} not permitted: it needs CAP_SYS_NICE or an rtprio limit of at least 10"
    try:
        assert served.state["scheduling"].startswith(f"normal scheduler ({refusal}")
        assert {policy for policy, _ in thread_policies(served.state["pid"])} == {os.SCHED_OTHER}

        def start(*args, **kwargs):
            return served.start_crest(*args, preexec_fn=without_realtime_privilege, **kwargs)

        run = start_circle(start, tmp_path / "run.csv", "--config", str(served.config))   # it runs: rows are written
        try:
            assert {policy for policy, _ in thread_policies(run.pid)} == {os.SCHED_OTHER}
        finally:
            stop(run)
        notices = [line for line in crest_lines(run.communicate()[1]) if "not permitted" in line]
        assert notices == [f"crest: {refusal} (`ulimit -r` is 0); the cycle runs under the normal scheduler"]
    finally:
        stop(served.process)
