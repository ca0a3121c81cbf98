"""The CLI on the virtual testbed, end to end: demo, runs, safety stops and their exit codes."""
import json
import signal
import subprocess
import time
import warnings

import can
import numpy as np
import pytest

from cli_runner import crest, edited_config, start_crest
from crest.driver import AXIS_ORDER
from crest.exit_codes import ExitCode
from crest.log import read_log
from crest.log.log_format import TruncatedLogWarning

START_TIMEOUT_S = 300.0      # boot, homing and the first rows of a run, on a loaded 2-core machine
# The runs that a signal ends are long runs in simulated time (--fast, as in test_cli_stops.py): a
# loaded machine cannot starve their drives' heartbeats into a stop of their own (in real time they
# stopped with HEARTBEAT_LOST before the signal), and boot and homing do not wait on the wall clock.


def test_demo_boots_homes_runs_the_paper_circle_and_records(tmp_path):
    result = crest("demo", "--fast", "--record", str(tmp_path))
    assert result.returncode == 0, result.stderr
    assert "booted 5 axes" in result.stdout and "homed" in result.stdout
    # the comparison says it ran on the controller's own model (the default Dahl plant): in family
    assert "plant: Dahl family" in result.stdout
    summary = result.stdout.split("the friction-aware feedforward cuts the tip error by")[1]
    assert "on the plant: Dahl family" in summary and "in family" in summary
    logs = sorted(tmp_path.glob("demo-*/circle-*.csv"))
    assert [log.stem for log in logs] == ["circle-cc", "circle-dahl"]
    for path in logs:
        log = read_log(path)
        assert len(log) > 1000 and log.tip_ref_mm is not None and log.tendon_force_n is not None
        assert log.plant.startswith("Dahl family") and "in family" in log.plant
        assert path.with_suffix(".blf").stat().st_size > 0
        frames = list(can.LogReader(path.with_suffix(".blf")))
        assert any(frame.arbitration_id == 0x80 for frame in frames)      # SYNC was recorded


@pytest.mark.parametrize("fault,code,axis", [
    ("tendon3:emcy@3.0", ExitCode.EMCY, "tendon3"),
    ("insertion:heartbeat@3.0", ExitCode.HEARTBEAT_LOST, "insertion"),
    ("tendon2:heartbeat@3.0", ExitCode.HEARTBEAT_LOST, "tendon2"),      # a tendon: its force cells too
    ("tendon1:stall@1.5", ExitCode.FOLLOWING_ERROR, "tendon1"),   # jammed while pulling
])
def test_a_drive_fault_stops_every_axis_with_its_exit_code_and_keeps_the_log(tmp_path, fault, code, axis):
    log_path = tmp_path / "run.csv"
    # at the homed free length (20 mm), where the sweep starts at once and the fault times were chosen
    result = crest("run", "builtin:sweep", "--articulation-deg", "90", "--insertion-mm", "20", "--fast",
                   "--fault", fault, "--record", str(log_path))
    assert result.returncode == code, result.stderr
    lines = [line for line in result.stderr.splitlines() if line.startswith("crest:")]
    assert len(lines) == 1 and axis in lines[0] and "Traceback" not in result.stderr
    log = read_log(log_path)
    assert len(log) > 50
    sidecar = json.loads(log_path.with_suffix(".json").read_text())
    assert axis in sidecar["summary"]["stop_cause"]
    if "heartbeat" in fault:     # the silent drive's rows hold no answer of it: the summary counts them
        unanswered = sidecar["summary"]["rows_without_drive_answer"]
        assert unanswered.get(axis, 0) >= 1, unanswered
        assert 2.95 <= sidecar["summary"]["first_row_without_drive_answer_s"][axis] <= 3.1   # at the fault (@3.0)
        _assert_only_the_silent_drives_cells_are_empty(log, axis, unanswered[axis])


def _assert_only_the_silent_drives_cells_are_empty(log, axis: str, rows: int) -> None:
    """The silent axis' position (and a tendon's force) cells are empty in exactly ``rows`` rows, from
    the fault (@3.0 s) on to the stop; in those rows every other axis' cells hold its answer."""
    k = AXIS_ORDER.index(axis)
    positions_mm = np.column_stack([log.tendon_pos_mm, log.insertion_pos_mm])
    empty = np.isnan(positions_mm[:, k])
    assert int(empty.sum()) == rows, (int(empty.sum()), rows)
    first = int(np.argmax(empty))
    assert 2.95 <= log.t_s[first] <= 3.1 and empty[first:].all(), log.t_s[empty]   # silent until the stop
    assert np.isfinite(np.delete(positions_mm, k, axis=1)[empty]).all()
    other_forces_n = log.tendon_force_n
    if k < 4:
        assert np.isnan(log.tendon_force_n[empty, k]).all() and np.isfinite(log.tendon_force_n[~empty, k]).all()
        other_forces_n = np.delete(log.tendon_force_n, k, axis=1)
    assert np.isfinite(other_forces_n[empty]).all()


def test_fault_times_count_from_the_start_of_the_run(tmp_path):
    """Boot, homing and the move out to the sweep's 80 mm free length take seconds; a fault at
    @0.5 lands half a second into the logged run, not during homing."""
    log_path = tmp_path / "run.csv"
    result = crest("run", "builtin:sweep", "--fast", "--fault", "tendon3:emcy@0.5", "--record", str(log_path))
    assert result.returncode == ExitCode.EMCY, result.stderr
    log = read_log(log_path)
    assert 0.4 <= log.t_s[-1] <= 0.8, log.t_s[-1]


def test_status_refuses_a_fault_it_would_never_inject():
    result = crest("status", "--fault", "tendon1:emcy@1")
    assert result.returncode == ExitCode.ERROR and "--fault does not apply to status" in result.stderr


def test_tracker_loss_in_a_closed_loop_run_stops_safely(tmp_path):
    log_path = tmp_path / "run.csv"
    result = crest("run", "builtin:sweep", "--controller", "dahl+fb", "--insertion-mm", "20", "--fast",
                   "--fault", "tracker:disconnect@3.0", "--record", str(log_path))
    assert result.returncode == ExitCode.TRACKER_LOST, result.stderr
    assert "tracker" in result.stderr
    assert len(read_log(log_path)) > 50


def test_target_outside_the_workspace_is_refused_before_anything_moves():
    result = crest("move", "--pitch", "400", "--yaw", "0")
    assert result.returncode == ExitCode.ERROR
    assert "booted" not in result.stdout
    assert "crest: error:" in result.stderr and "Traceback" not in result.stderr


def test_nan_target_is_refused():
    result = crest("move", "--pitch", "nan", "--yaw", "0")
    assert result.returncode == ExitCode.ERROR
    assert "finite" in result.stderr


def test_too_fast_setpoint_file_is_refused_before_anything_moves(tmp_path):
    path = tmp_path / "fast.csv"
    path.write_text("t,tendon_cmd_1,tendon_cmd_2,tendon_cmd_3,tendon_cmd_4,insertion_cmd\n"
                    "0,0,0,0,0,22\n0.01,5,0,-5,0,22\n")
    result = crest("run", str(path), "--fast")
    assert result.returncode == ExitCode.ERROR
    assert "tendon1" in result.stderr and "Traceback" not in result.stderr


def test_bad_configuration_names_the_file_and_field(tmp_path):
    bad = edited_config(tmp_path, period_s=-1.0)
    result = crest("status", "--config", str(bad))
    assert result.returncode == ExitCode.CONFIG
    assert "sync.period_s" in result.stderr and str(bad) in result.stderr


def test_a_testbed_with_a_40_ms_sync_moves_to_its_target(tmp_path):
    """A slow SYNC is the user's choice: the virtual drives keep their own 10 ms position loops
    (before, at 40 ms the simulated servo oscillated and the move ended in a safety stop)."""
    config = edited_config(tmp_path, period_s=0.04)
    result = crest("move", "--pitch", "30", "--yaw", "0", "--fast", "--config", str(config))
    assert result.returncode == ExitCode.OK, result.stderr
    assert "safety stop" not in result.stderr
    assert "from the target" in result.stdout


def test_bad_command_line_arguments_exit_with_usage():
    result = crest("move", "--pitch", "ten", "--yaw", "0")
    assert result.returncode == ExitCode.USAGE
    assert "invalid float value" in result.stderr


@pytest.mark.parametrize("inherited_sigint", [signal.SIG_DFL, signal.SIG_IGN])   # SIG_IGN: started by a shell
def test_ctrl_c_stops_every_axis_and_saves_the_log(tmp_path, inherited_sigint):      # in the background
    log_path = tmp_path / "run.csv"
    process = start_crest("run", "builtin:circle", "--periods", "100", "--fast", "--record", str(log_path),
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                          preexec_fn=lambda: signal.signal(signal.SIGINT, inherited_sigint))
    deadline = time.monotonic() + START_TIMEOUT_S
    while not log_path.exists() or log_path.stat().st_size < 2000:
        assert time.monotonic() < deadline and process.poll() is None
        time.sleep(0.1)
    process.send_signal(signal.SIGINT)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == ExitCode.INTERRUPTED, stderr
    assert "Ctrl-C" in stderr
    sidecar = json.loads(log_path.with_suffix(".json").read_text())
    assert "stop_cause" in sidecar["summary"]
    assert len(read_log(log_path)) > 10


def test_killed_process_leaves_a_readable_log(tmp_path):
    log_path = tmp_path / "run.csv"
    process = start_crest("run", "builtin:circle", "--periods", "100", "--fast", "--record", str(log_path))
    deadline = time.monotonic() + START_TIMEOUT_S
    while not log_path.exists() or log_path.read_bytes().count(b"\n") < 151:   # header and 150 rows on disk
        assert time.monotonic() < deadline and process.poll() is None
        time.sleep(0.1)
    process.kill()                     # SIGKILL: no handler runs, nothing is flushed at exit
    process.wait(timeout=30)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TruncatedLogWarning)   # a partly written last line is allowed
        log = read_log(log_path)
    assert len(log) >= 150


def test_move_that_loses_the_tracker_reports_no_tip_instead_of_the_last_one_seen():
    result = crest("move", "--pitch", "60", "--yaw", "0", "--insertion", "80", "--fast",
                   "--fault", "tracker:disconnect@0.3")
    assert result.returncode == 0, result.stderr
    assert not any(line.startswith("tracked tip") for line in result.stdout.splitlines())  # a frame from before the loss
    assert "no tracked tip at the end: tracker lost at" in result.stdout
