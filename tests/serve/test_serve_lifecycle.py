"""`crest testbed serve`: where it says its bus and tracker are, one server at a time, a clean
stop on SIGTERM, and a killed server's state file recognised as stale."""
import os
import re
import socket

import pytest

from crest.exit_codes import ExitCode
from served_testbed import crest_lines, process_alive, start_served_testbed, stop


def test_serve_publishes_its_bus_and_tracker_refuses_a_second_server_and_cleans_up_on_sigterm(tmp_path):
    served = start_served_testbed(tmp_path)
    try:
        state = served.state
        assert state["pid"] == served.process.pid
        assert state["bus_interface"] == "remote"
        port = int(re.fullmatch(r"ws://127\.0\.0\.1:(\d+)/", state["bus_channel"]).group(1))
        assert os.path.exists(state["tracker_port"])
        assert state["config"] == str(served.config.resolve())
        second = served.crest("testbed", "serve", "--config", str(served.config), timeout_s=120)
        assert second.returncode == ExitCode.ERROR, second.stderr
        lines = crest_lines(second.stderr)
        assert len(lines) == 1 and "already running" in lines[0] and f"pid {state['pid']}" in lines[0], second.stderr
        assert served.state == state                 # the refused server left the running one alone
    finally:
        stop(served.process)
    stdout, stderr = served.process.communicate()
    assert served.process.returncode == ExitCode.OK, stderr
    assert state["bus_channel"] in stdout and state["tracker_port"] in stdout
    assert crest_lines(stderr)[-1] == "crest testbed serve: stopped by SIGTERM" and "Traceback" not in stderr
    assert not served.state_file.exists()
    with pytest.raises(OSError):                     # nothing listens on the bus's port any more
        socket.create_connection(("127.0.0.1", port), timeout=5).close()


def test_a_killed_server_leaves_a_stale_state_file_that_nothing_joins_and_the_next_server_replaces(tmp_path):
    first = start_served_testbed(tmp_path)
    first.process.kill()                             # kill -9: no clean-up
    first.process.communicate()
    assert first.state_file.exists() and not process_alive(first.state["pid"])
    estop = first.crest("estop", "--config", str(first.config), timeout_s=120)
    assert estop.returncode == ExitCode.ERROR and estop.stdout == ""
    assert "no virtual testbed is running" in estop.stderr and "crest testbed serve" in estop.stderr
    second = start_served_testbed(tmp_path, first.config)
    try:
        assert second.state["pid"] == second.process.pid != first.process.pid
    finally:
        stop(second.process)
    assert second.process.returncode == ExitCode.OK


def test_commands_that_cannot_join_the_served_testbed_refuse_and_leave_it_alone(tmp_path):
    served = start_served_testbed(tmp_path)
    try:
        other_config = served.crest("status")        # configs/testbed.toml: other heartbeat timings
        assert other_config.returncode == ExitCode.ERROR and other_config.stdout == ""
        assert "serves the drives of" in other_config.stderr and "--config" in other_config.stderr
        with_fault = served.crest("run", "builtin:circle", "--config", str(served.config),
                                  "--fault", "tendon1:emcy@1.0")
        assert with_fault.returncode == ExitCode.ERROR and "--fault" in crest_lines(with_fault.stderr)[0]
        assert "a served one is running" in with_fault.stderr
        assert served.process.poll() is None
    finally:
        stop(served.process)
    assert served.process.returncode == ExitCode.OK
