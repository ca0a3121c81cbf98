"""A command joined to the served testbed runs beside it, on the other CPUs, while its session is
open, every thread included, and gets all its CPUs back afterwards."""
import os
import threading

import pytest

from crest.testbed_service import cpu_split

pytestmark = pytest.mark.skipif(len(os.sched_getaffinity(0)) < 2, reason="with one CPU nothing is pinned")


def test_a_process_beside_the_testbed_runs_on_the_other_cpus_and_gets_them_back_after():
    before = os.sched_getaffinity(0)
    testbed = cpu_split.testbed_cpus()
    assert testbed == (max(before),)
    seen = {}
    started, asked, answered = threading.Event(), threading.Event(), threading.Event()

    def thread_started_before():
        started.set()
        asked.wait(60)
        seen["thread"] = os.sched_getaffinity(0)
        answered.set()

    thread = threading.Thread(target=thread_started_before)
    thread.start()
    started.wait(60)
    with cpu_split.beside(testbed):
        seen["main"] = os.sched_getaffinity(0)
        asked.set()
        answered.wait(60)
    thread.join(60)
    assert seen["main"] == seen["thread"] == before - set(testbed)
    assert os.sched_getaffinity(0) == before


def test_nothing_is_pinned_beside_a_testbed_that_is_not():
    before = os.sched_getaffinity(0)
    with cpu_split.beside(()):
        assert os.sched_getaffinity(0) == before
