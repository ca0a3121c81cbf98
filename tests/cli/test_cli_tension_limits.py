"""Operator commands stay inside the tendon tension limit: the paper's scenarios run, and what would
exceed max_tension_n (40 N) is refused before motion with the tension it needs (issue 15, items 7-8)."""
import numpy as np
import pytest

from cli_runner import crest
from crest.exit_codes import ExitCode
from crest.log import read_log

MAX_TENSION_N = 40.0   # configs/testbed.toml [axis_defaults.tendon].max_tension_n


@pytest.mark.parametrize("scenario,degrees", [("sweep", "180"), ("circle", "195")])
def test_paper_scenarios_run_on_the_default_testbed_without_a_safety_stop(tmp_path, scenario, degrees):
    log_path = tmp_path / "run.csv"
    result = crest("run", f"builtin:{scenario}", "--articulation-deg", degrees, "--periods", "1", "--fast",
                   "--record", str(log_path), timeout_s=900.0)
    assert result.returncode == ExitCode.OK, result.stderr
    log = read_log(log_path)
    assert log.insertion_cmd_mm[0] == pytest.approx(80.0, abs=0.1)       # at the working free length
    measured_max_n = np.nanmax(log.tendon_force_n)      # over the drives' answers (NaN: an answer did not come)
    assert measured_max_n < MAX_TENSION_N
    assert measured_max_n > 10.0                                         # and the catheter was bent


def test_move_that_needs_more_than_the_tension_limit_is_refused_before_motion(tmp_path):
    log_path = tmp_path / "move.csv"
    result = crest("move", "--pitch", "200", "--yaw", "0", "--fast", "--record", str(log_path))
    assert result.returncode == ExitCode.ERROR, result.stderr
    assert "TENSION_LIMIT" not in result.stderr and "Traceback" not in result.stderr
    line = result.stderr.strip()
    assert "refused before motion" in line and "tendon1" in line and "max_tension_n 40 N" in line
    needed_n = float(line.split("needs ")[1].split(" N")[0])
    assert needed_n > MAX_TENSION_N
    assert not log_path.exists()                                          # no session was opened


def test_setpoint_file_needing_too_much_tension_is_refused_before_motion(tmp_path):
    path = tmp_path / "pull.csv"             # tendon 1 pulled 6 mm (137 deg) at the homed 20 mm free length
    path.write_text("t,tendon_cmd_1,tendon_cmd_2,tendon_cmd_3,tendon_cmd_4,insertion_cmd\n"
                    "0,0.005,0.005,0.005,0.005,20\n10,6.005,0.005,-5.995,0.005,20\n")
    result = crest("run", str(path), "--fast", "--record", str(tmp_path / "run.csv"))
    assert result.returncode == ExitCode.ERROR, result.stderr
    assert "refused before motion" in result.stderr and "tendon1" in result.stderr
    assert not (tmp_path / "run.csv").exists()


def test_builtin_beyond_the_tension_limit_at_a_short_free_length_is_refused_before_motion(tmp_path):
    result = crest("run", "builtin:sweep", "--articulation-deg", "120", "--insertion-mm", "20", "--fast",
                   "--record", str(tmp_path / "run.csv"))
    assert result.returncode == ExitCode.ERROR, result.stderr
    assert "refused before motion" in result.stderr and "tendon1" in result.stderr
    assert not (tmp_path / "run.csv").exists()
