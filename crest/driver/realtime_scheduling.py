"""Real-time scheduling for the SYNC cycle: every thread of the process under SCHED_FIFO.

Under Linux's normal scheduler a thread of either process (the master's receive thread, the
tracker, the testbed's bus threads) can run in the cycle's way, and the SYNC then leaves a
millisecond or more late. Under SCHED_FIFO a thread that becomes ready runs before every normal
thread on its CPU, so the cycle waits only on its own work. The README ("Full stack across the
process boundary") gives the measurement, with and without.

`realtime_threads(priority)` puts every thread of this process under SCHED_FIFO at `priority`
(1..99) until the block ends, then back to what each had. Threads and processes started inside
the block inherit it (a new task takes its creator's policy): the bus server's thread for each
client, for instance. (SCHED_RESET_ON_FORK would keep processes out, but Linux applies it to new
threads as well, and those threads are on the cycle's path.) Priority 0 changes nothing.

Linux grants SCHED_FIFO to a process with CAP_SYS_NICE (root) or with an rtprio limit of at
least `priority` (`ulimit -r`; for a user, a line ``USER - rtprio 20`` in
/etc/security/limits.conf). Where it is not granted nothing changes, and the returned
`Scheduling` says why. A real-time thread that never blocks cannot lock the machine up: Linux
keeps 5% of every second for normal threads (kernel.sched_rt_runtime_us).
"""
from __future__ import annotations

import os
import resource
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass


@dataclass(frozen=True)
class Scheduling:
    """What the threads run under: SCHED_FIFO at `priority`, or (priority 0) the normal scheduler;
    `refused` says why a requested priority was not granted."""

    priority: int = 0
    refused: str = ""

    def describe(self) -> str:
        if self.priority:
            return f"real-time (SCHED_FIFO, priority {self.priority})"
        return "normal scheduler" + (f" ({self.refused})" if self.refused else "")


def thread_ids() -> list[int]:
    """The kernel's ids of this process's threads (on Linux each thread has its own CPU mask and
    scheduling policy, so a setting for the process is one call per thread). [0], the calling
    thread, where /proc cannot say."""
    try:
        return [int(name) for name in os.listdir("/proc/self/task")]
    except OSError:
        return [0]


@contextmanager
def realtime_threads(priority: int) -> Iterator[Scheduling]:
    """This process's threads under SCHED_FIFO at `priority` until the block ends (see module doc);
    yields what they got."""
    if not priority:
        yield Scheduling()
        return
    policy = getattr(os, "SCHED_FIFO", None)
    if policy is None:
        yield Scheduling(refused=f"real-time priority {priority} asked for, but this platform has no SCHED_FIFO")
        return
    before = {thread: _policy_of(thread) for thread in thread_ids()}
    try:
        os.sched_setscheduler(0, policy, os.sched_param(priority))
    except PermissionError:
        limit = resource.getrlimit(resource.RLIMIT_RTPRIO)[0]
        yield Scheduling(refused=f"real-time priority {priority} not permitted: it needs CAP_SYS_NICE "
                                 f"or an rtprio limit of at least {priority} (`ulimit -r` is {limit})")
        return
    for thread in before:
        _set(thread, policy, priority)
    try:
        yield Scheduling(priority)
    finally:
        for thread in thread_ids():
            _set(thread, *before.get(thread, (os.SCHED_OTHER, 0)))


def _policy_of(thread: int) -> tuple[int, int]:
    try:
        return os.sched_getscheduler(thread), os.sched_getparam(thread).sched_priority
    except ProcessLookupError:
        return os.SCHED_OTHER, 0


def _set(thread: int, policy: int, priority: int) -> None:
    try:
        os.sched_setscheduler(thread, policy, os.sched_param(priority))
    except ProcessLookupError:
        pass    # the thread ended meanwhile
