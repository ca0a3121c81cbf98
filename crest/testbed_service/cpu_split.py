"""The served testbed and the command that drives it run on CPUs of their own.

Each of the two processes is held to about one CPU by its interpreter lock, and on every SYNC they
take turns: the master sends, the testbed's drives answer, the master reads the answers. Left to
the scheduler, a thread of one process (the testbed's bus threads, the master's receive thread)
often runs on the CPU the other's cycle needs, and that SYNC leaves a millisecond or more late.
So on a machine where the testbed may use at least two CPUs, it takes the last one
(`testbed_cpus`, recorded in its state file), and a command joined to it runs on the others while
its session is open (`beside`). With a single CPU nothing is pinned.

The README ("Full stack across the process boundary") gives the measurement: the 500 Hz full
stack, 20 s, with the two processes pinned apart by hand against not pinned.
"""
from __future__ import annotations

import os
from collections.abc import Iterator, Sequence
from contextlib import contextmanager

from crest.driver.realtime_scheduling import thread_ids


def allowed_cpus() -> tuple[int, ...]:
    """The CPUs this thread may run on (empty where the platform cannot say)."""
    if not hasattr(os, "sched_getaffinity"):
        return ()
    return tuple(sorted(os.sched_getaffinity(0)))


def testbed_cpus() -> tuple[int, ...]:
    """The CPU a served testbed takes: the last one allowed, where at least two are (else none)."""
    cpus = allowed_cpus()
    return cpus[-1:] if len(cpus) >= 2 else ()


def pin_process(cpus: Sequence[int]) -> None:
    """Every thread of this process on `cpus`; threads it starts later inherit it (on Linux each
    thread has its own CPU mask, so one call for the process is not enough)."""
    for thread in thread_ids():
        try:
            os.sched_setaffinity(thread, cpus)
        except ProcessLookupError:
            pass    # the thread ended meanwhile


@contextmanager
def beside(testbed: Sequence[int]) -> Iterator[None]:
    """This process on its allowed CPUs other than `testbed`'s until the block ends, then back on
    all it had; unchanged where that would leave it none (or `testbed` is empty)."""
    before = allowed_cpus()
    rest = [cpu for cpu in before if cpu not in testbed]
    if not testbed or not rest:
        yield
        return
    pin_process(rest)
    try:
        yield
    finally:
        pin_process(before)
