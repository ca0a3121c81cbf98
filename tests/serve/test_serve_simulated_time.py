"""Simulated time across the process boundary. A command run with --fast starts a testbed process
of its own, as every command does, and moves its clock with CANopen TIME stamps on the bus
(sim_backend.time_stamps): other processes reach it as they reach a real-time one, and faults cross
the boundary the same way. A real-time command cannot use a testbed served in simulated time."""
import json
import subprocess

import can
import pytest

from crest.exit_codes import ExitCode
from crest.log import read_log
from served_testbed import (crest_lines, rows_on_disk, start_circle, start_served_testbed, stop, wait_for_rows,
                            wait_gone)
from sim_backend.time_stamps import TIME_COB_ID, time_stamp_seconds
from tests.cli.cli_runner import crest, start_crest

AXES = ("tendon1", "tendon2", "tendon3", "tendon4", "insertion")


@pytest.fixture
def fast_run(tmp_path, own_runtime_dir):
    """A long `crest run builtin:circle --fast` with a testbed of its own, writing rows: (the run, its
    log path, the state file of its testbed)."""
    log_path = tmp_path / "run.csv"
    run = start_circle(start_crest, log_path, "--fast")
    try:
        yield run, log_path, own_runtime_dir / "crest" / "testbed.json"
    finally:
        stop(run)


def time_stamps_s(blf_path):
    return [time_stamp_seconds(f.data) for f in can.LogReader(blf_path) if f.arbitration_id == TIME_COB_ID]


def test_a_fast_run_drives_its_own_testbed_process_by_time_stamps_and_estop_from_another_process_stops_it(
        fast_run):
    run, log_path, state_file = fast_run
    state = json.loads(state_file.read_text())
    estop = crest("estop")
    _, stderr = run.communicate(timeout=120)
    assert state["simulated_time"] is True and state["pid"] != run.pid
    assert estop.returncode == ExitCode.OK, estop.stdout + estop.stderr
    assert [line.split()[:2] for line in estop.stdout.splitlines()] == [[axis, "stopped"] for axis in AXES]
    lines = crest_lines(stderr)
    assert run.returncode == ExitCode.ERROR and len(lines) == 1 and "crest estop" in lines[0], stderr
    stamps = time_stamps_s(log_path.with_suffix(".blf"))
    assert len(stamps) >= 20 and stamps == sorted(stamps)
    assert stamps[-1] >= read_log(log_path).t_s[-1]     # the testbed's clock kept up with the log's
    wait_gone(state["pid"], state_file)


def test_kill_9_of_a_testbed_in_simulated_time_stops_the_fast_run_on_every_axis_heartbeat_lost(fast_run):
    run, log_path, state_file = fast_run
    subprocess.run(["kill", "-9", str(json.loads(state_file.read_text())["pid"])], check=True)
    _, stderr = run.communicate(timeout=120)
    assert run.returncode == ExitCode.HEARTBEAT_LOST, stderr
    lines = crest_lines(stderr)
    assert len(lines) == 1 and "Traceback" not in stderr, stderr
    named = lines[0].split("(HEARTBEAT_LOST): ")[1].split(": no heartbeat from ")[0]
    assert sorted(named.split(", ")) == sorted(AXES), lines[0]
    summary = json.loads(log_path.with_suffix(".json").read_text())["summary"]
    assert summary["exit_code"] == ExitCode.HEARTBEAT_LOST and len(read_log(log_path)) >= 20


def test_a_testbed_served_in_simulated_time_refuses_real_time_commands_and_follows_a_fast_one(tmp_path):
    served = start_served_testbed(tmp_path, None, "--simulated-time")
    try:
        assert served.state["simulated_time"] is True
        status = served.crest("status", "--config", str(served.config))
        log_path = tmp_path / "run.csv"
        run = served.crest("run", "builtin:circle", "--config", str(served.config), "--fast", "--insertion-mm", "25",
                           "--periods", "1", "--record", str(log_path))
        still_serving = served.process.poll() is None
    finally:
        stop(served.process)
    assert status.returncode == ExitCode.ERROR and "--fast" in status.stderr and status.stdout == "", status.stderr
    assert run.returncode == ExitCode.OK, run.stderr
    stamps = time_stamps_s(log_path.with_suffix(".blf"))
    assert stamps and stamps[-1] >= read_log(log_path).t_s[-1]
    assert still_serving        # the command drove the served testbed; it did not start or stop one


def test_a_second_fast_run_beside_one_that_drives_its_testbed_keeps_its_testbed_in_its_own_process(fast_run, tmp_path):
    """One command drives a testbed's simulated clock: a second `--fast` run does not join the first
    one's testbed process (it would move the same clock), but runs its own testbed inside itself."""
    first, first_log, state_file = fast_run
    testbed_pid = json.loads(state_file.read_text())["pid"]
    second_log = tmp_path / "second.csv"
    second = crest("run", "builtin:circle", "--fast", "--insertion-mm", "25", "--periods", "1",
                   "--record", str(second_log))
    assert second.returncode == ExitCode.OK, second.stderr
    assert time_stamps_s(second_log.with_suffix(".blf")) == []          # its clock drove no other process
    assert first.poll() is None and json.loads(state_file.read_text())["pid"] == testbed_pid
    rows = rows_on_disk(first_log)
    wait_for_rows(first_log, rows + 20, first)                         # the first run goes on


def test_a_fault_lands_at_the_same_simulated_time_across_the_boundary_as_inside_one_process(tmp_path):
    """The fault clock starts on the bus in order with the TIME stamps, and the testbed compares
    times in whole microseconds: a `--fault` stops the run on the same cycle either way."""
    logs = {}
    for mode in ("process", "in-process"):
        logs[mode] = tmp_path / f"{mode}.csv"
        result = crest("run", "builtin:sweep", "--fast", "--fault", "tendon3:emcy@0.5", "--record", str(logs[mode]),
                       env={"CREST_VIRTUAL_TESTBED": mode})
        assert result.returncode == ExitCode.EMCY, result.stderr
    assert time_stamps_s(logs["process"].with_suffix(".blf"))          # that run crossed the boundary
    across, inside = (read_log(logs[mode]).t_s for mode in ("process", "in-process"))
    assert list(across) == list(inside) and 0.45 <= across[-1] < 0.5
