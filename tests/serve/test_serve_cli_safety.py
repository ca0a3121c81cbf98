"""The CLI's safety stops across the process boundary, as an operator meets them by default.

A real-time crest command that finds no served testbed starts one in a process of its own
(crest.testbed_service.auto_start) and drives it through python-can's remote interface: faults
happen in that process, and reach the command only as frames on the bus and bytes on the
tracker's pseudo-terminal, as on hardware. The same stops are tested inside one process, in
simulated time, in tests/cli; here each runs in real time on the relaxed configuration of
served_testbed.py (a loaded machine must not trip a heartbeat loss the test did not cause).
Every test checks that the testbed process ended with its command.
"""
import json
import signal
import subprocess
from pathlib import Path

import pytest

from crest.exit_codes import ExitCode
from crest.log import read_log
from served_testbed import HEARTBEAT_TIMEOUT_S, crest_lines, relaxed_config, stop, wait_for_rows, wait_gone
from tests.cli.cli_runner import assert_every_drive_quick_stopped, crest, start_crest

DETECTION_S = 1.5                   # an EMCY or a following error reaches the master well within this
# The fault clock starts just before the trajectory's first set-point, as in tests/cli's
# test_fault_times_count_from_the_start_of_the_run; the log's time is the set-points' own.
CLOCK_LEAD_S = 0.1


def state_file(runtime_dir: Path) -> Path:
    return runtime_dir / "crest" / "testbed.json"


def sweep_with_fault(tmp_path: Path, fault: str, *options: str) -> tuple[subprocess.CompletedProcess, Path]:
    """A real-time `crest run builtin:sweep` at the homed free length (20 mm, where the sweep starts at
    once) with `fault` and `options`, recorded; (the finished command, its log path)."""
    log_path = tmp_path / "run.csv"
    result = crest("run", "builtin:sweep", "--config", str(relaxed_config(tmp_path / "config")), "--insertion-mm",
                   "20", *options, "--fault", fault, "--record", str(log_path))
    return result, log_path


@pytest.mark.parametrize("fault,at_s,code,axis,silent_node", [
    ("tendon3:emcy", 3.0, ExitCode.EMCY, "tendon3", None),
    ("insertion:heartbeat", 3.0, ExitCode.HEARTBEAT_LOST, "insertion", 5),
    ("tendon1:stall", 1.5, ExitCode.FOLLOWING_ERROR, "tendon1", None),    # jammed while pulling
])
def test_a_fault_in_the_testbed_process_stops_every_axis_with_its_exit_code_at_its_time(
        tmp_path, own_runtime_dir, fault, at_s, code, axis, silent_node):
    """The fault's time counts from the start of the run's motion (the command tells its testbed
    process when that is), not from the testbed's start: boot and homing come first."""
    result, log_path = sweep_with_fault(tmp_path, f"{fault}@{at_s}", "--articulation-deg", "90")
    assert result.returncode == code, result.stderr
    lines = crest_lines(result.stderr)
    assert len(lines) == 1 and axis in lines[0] and "Traceback" not in result.stderr
    sidecar = json.loads(log_path.with_suffix(".json").read_text())
    assert axis in sidecar["summary"]["stop_cause"] and sidecar["summary"]["exit_code"] == code
    log = read_log(log_path)
    latest_s = at_s + (HEARTBEAT_TIMEOUT_S if "heartbeat" in fault else 0.0) + DETECTION_S
    assert at_s - CLOCK_LEAD_S <= log.t_s[-1] <= latest_s, log.t_s[-1]
    assert_every_drive_quick_stopped(log_path.with_suffix(".blf"), silent_node)
    assert not state_file(own_runtime_dir).exists()


@pytest.mark.parametrize("stop_signal,code,name", [
    (signal.SIGTERM, ExitCode.TERMINATED, "SIGTERM"),
    (signal.SIGINT, ExitCode.INTERRUPTED, "Ctrl-C"),
])
def test_a_stop_signal_stops_every_axis_saves_the_log_and_ends_the_testbed_process(
        tmp_path, own_runtime_dir, stop_signal, code, name):
    log_path = tmp_path / "run.csv"
    run = start_crest("run", "builtin:circle", "--config", str(relaxed_config(tmp_path / "config")),
                      "--insertion-mm", "25", "--periods", "100", "--record", str(log_path),
                      stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        wait_for_rows(log_path, 20, run)
        testbed_pid = json.loads(state_file(own_runtime_dir).read_text())["pid"]
        run.send_signal(stop_signal)
        _, stderr = run.communicate(timeout=60)
    finally:
        stop(run)
    assert run.returncode == code, stderr
    lines = crest_lines(stderr)
    assert len(lines) == 1 and name in lines[0] and "Traceback" not in stderr
    sidecar = json.loads(log_path.with_suffix(".json").read_text())
    assert name in sidecar["summary"]["stop_cause"] and sidecar["summary"]["exit_code"] == code
    assert len(read_log(log_path)) >= 20
    assert_every_drive_quick_stopped(log_path.with_suffix(".blf"))
    wait_gone(testbed_pid, state_file(own_runtime_dir))


def test_a_drive_that_stops_answering_sdo_in_the_testbed_process_ends_in_an_sdo_safety_stop(tmp_path,
                                                                                          own_runtime_dir):
    result, log_path = sweep_with_fault(tmp_path, "tendon2:sdo_timeout@1", "--articulation-deg", "90")
    assert result.returncode == ExitCode.SDO_FAILURE, result.stderr
    lines = crest_lines(result.stderr)
    assert len(lines) == 1 and "tendon2" in lines[0] and "SDO" in lines[0]
    sidecar = json.loads(log_path.with_suffix(".json").read_text())
    assert "tendon2" in sidecar["summary"]["stop_cause"] and sidecar["summary"]["exit_code"] == ExitCode.SDO_FAILURE
    assert not state_file(own_runtime_dir).exists()


def test_tracker_loss_in_the_testbed_process_stops_a_closed_loop_run_safely(tmp_path, own_runtime_dir):
    """The simulated tracker runs in the testbed process, on its pseudo-terminal; its loss reaches the
    command as a silent serial port."""
    result, log_path = sweep_with_fault(tmp_path, "tracker:disconnect@3.0", "--controller", "dahl+fb")
    assert result.returncode == ExitCode.TRACKER_LOST, result.stderr
    lines = crest_lines(result.stderr)
    assert len(lines) == 1 and "tracker" in lines[0].lower() and "Traceback" not in result.stderr
    assert_every_drive_quick_stopped(log_path.with_suffix(".blf"))
    assert not state_file(own_runtime_dir).exists()
