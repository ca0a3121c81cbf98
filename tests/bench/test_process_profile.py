"""The per-process profile of `crest bench --only stack_profile` (crest.bench.process_profile): py-spy
and the kernel's per-thread CPU counts, for real, on a process that started a child, each spinning
in code of a known component."""
import subprocess
import sys
import textwrap
import threading

import pytest

from crest.bench.process_profile import (RUNTIME, ProcessTreeProfile, ProfilerUnavailable, component_of,
                                         thread_components)

SPIN = "def spin():\n    while True:\n        sum(range(1000))\n"


def test_a_stack_belongs_to_the_innermost_component_it_passes_through():
    transport_write = ["<module> (/x/crest/cli/main.py:1)", "run (/x/crest/driver/sync_cycle.py:9)",
                       "send (/x/site-packages/can_remote/websocket.py:5)", "sendall (/usr/lib/python3.11/socket.py:2)"]
    assert component_of(transport_write) == "WebSocket transport (python-can-remote)"
    assert component_of(["<module> (/x/crest/cli/main.py:1)", "run (/x/model/quasi_static_kernel.py:3)"]) \
        == "model (model/)"
    assert component_of(["_bootstrap (/usr/lib/python3.11/threading.py:1)"]) == RUNTIME


def test_a_thread_that_the_threading_module_never_named_is_still_counted(tmp_path):
    raw = tmp_path / "raw.txt"
    raw.write_text("thread (41);<module> (/x/model/spin.py:4);spin (/x/model/spin.py:3) 99\n"
                   "thread (42): Thread-1 (work);run (/x/control/dahl.py:7) 3\n")
    names, counts = thread_components(raw)
    assert names == {41: "(no name)", 42: "Thread-1 (work)"}
    assert counts[41] == {"model (model/)": 99} and counts[42] == {"controller (control/)": 3}


def test_a_process_and_its_child_each_get_their_cpu_and_the_component_they_spend_it_in(tmp_path):
    child_script = tmp_path / "sim_backend" / "plant" / "spin.py"
    parent_script = tmp_path / "model" / "spin.py"
    for script in (child_script, parent_script):
        script.parent.mkdir(parents=True)
    child_script.write_text(SPIN + "spin()\n")
    parent_script.write_text(textwrap.dedent(f"""
        import subprocess, sys, time
        child = subprocess.Popen([sys.executable, {str(child_script)!r}])
        print(child.pid, flush=True)
    """) + SPIN + "spin()\n")
    process = subprocess.Popen([sys.executable, str(parent_script)], stdout=subprocess.PIPE, text=True)
    child_pid = int(process.stdout.readline())
    try:
        profile = ProcessTreeProfile(process.pid, tmp_path / "profile", 50)
        profile.start(3.0)
        rows = {row["pid"]: row for row in profile.finish(timeout_s=120.0)}
    except ProfilerUnavailable as error:
        pytest.skip(f"this system does not let py-spy read another process: {error}")
    finally:
        subprocess.run(["kill", "-9", str(child_pid)], check=False)
        process.kill()
        process.wait()
    assert set(rows) == {process.pid, child_pid}
    assert str(child_script) in rows[child_pid]["command"]
    for pid, component in ((process.pid, "model (model/)"), (child_pid, "plant (sim_backend/plant/)")):
        spinner = rows[pid]["threads"][0]                     # the thread with the most CPU
        assert spinner["name"] in ("MainThread", "(no name)") and spinner["samples"] > 0
        assert max(spinner["components"], key=spinner["components"].get) == component
        assert abs(sum(spinner["components"].values()) - 1.0) < 1e-9
        cpu = spinner["cpu_user"] + spinner["cpu_kernel"]
        assert 0.05 < cpu <= 1.05                              # one thread, however loaded the machine
        assert spinner["cpu_user"] > spinner["cpu_kernel"]      # it spins in Python, not in the kernel
        assert rows[pid]["cpu_user"] == pytest.approx(sum(t["cpu_user"] for t in rows[pid]["threads"]))


def test_a_process_that_is_not_there_is_a_clear_error_from_finish_and_no_profiler_starts(tmp_path):
    """The bench starts the profile in a timer thread, so the error must reach the caller's finish."""
    profile = ProcessTreeProfile(2 ** 22 + 12345, tmp_path / "profile", 50)     # a pid that does not exist
    starter = threading.Timer(0.0, profile.start, args=(1.0,))
    starter.start()
    starter.join()
    with pytest.raises(ProfilerUnavailable, match=f"no process {2 ** 22 + 12345} to profile"):
        profile.finish(timeout_s=60.0)
    assert not list((tmp_path / "profile").glob("profile_*.txt"))
