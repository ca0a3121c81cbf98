"""Bad input is refused before anything moves, with a line a person can act on; no option is ignored."""
import json

import pytest

from cli_runner import crest
from crest.cli.gap_command import format_score
from crest.exit_codes import ExitCode
from crest.log import read_log
from model.effects import EFFECTS
from sim_backend.faults import FaultKind

SLOW_SETPOINTS = ("t,tendon_cmd_1,tendon_cmd_2,tendon_cmd_3,tendon_cmd_4,insertion_cmd\n"
                  "0,0,0,0,0,22\n2,0.5,0,-0.5,0,22\n")


def error_lines(result) -> list[str]:
    return [line for line in result.stderr.splitlines() if line.startswith("crest")]


def assert_refused_before_boot(result, code=ExitCode.ERROR) -> str:
    """One error line, no traceback, and no drive ever booted or homed."""
    assert result.returncode == code, result.stderr
    assert "Traceback" not in result.stderr
    assert "booted" not in result.stdout and "homed" not in result.stdout and "ran " not in result.stdout
    return result.stderr


def test_record_to_an_existing_log_is_refused_before_boot_and_the_file_is_kept(tmp_path):
    log_path = tmp_path / "run.csv"
    log_path.write_text("an earlier run\n")
    stderr = assert_refused_before_boot(crest("run", "builtin:sweep", "--fast", "--record", str(log_path)))
    assert f"{log_path} exists; pass --overwrite to replace it" in stderr
    assert log_path.read_text() == "an earlier run\n"


def test_record_refuses_an_existing_sidecar_too(tmp_path):
    (tmp_path / "run.json").write_text("{}")
    stderr = assert_refused_before_boot(crest("move", "--pitch", "10", "--yaw", "0", "--fast",
                                              "--record", str(tmp_path / "run.csv")))
    assert "run.json exists" in stderr and "--overwrite" in stderr


def test_overwrite_replaces_an_existing_log(tmp_path):
    log_path = tmp_path / "run.csv"
    log_path.write_text("an earlier run\n")
    setpoints = tmp_path / "slow.csv"
    setpoints.write_text(SLOW_SETPOINTS)
    result = crest("run", str(setpoints), "--fast", "--record", str(log_path), "--overwrite")
    assert result.returncode == 0, result.stderr
    assert len(read_log(log_path)) > 100                              # 2 s at the 100 Hz SYNC
    assert json.loads(log_path.with_suffix(".json").read_text())["source"].endswith(f"set-points {setpoints}")


def test_excite_refuses_an_existing_log_in_its_folder_before_boot(tmp_path):
    (tmp_path / "holdout.csv").write_text("an earlier run\n")
    stderr = assert_refused_before_boot(crest("excite", "--short", "--fast", "--record", str(tmp_path)))
    assert "holdout.csv exists; pass --overwrite" in stderr


def test_an_output_under_a_file_is_refused_before_the_fit(tmp_path):
    blocker = tmp_path / "results"
    blocker.write_text("")
    log = tmp_path / "train.csv"
    result = crest("fit", str(log), "--out", str(blocker / "catheter.toml"))
    assert result.returncode == ExitCode.ERROR
    assert f"{blocker} is a file, not a folder" in result.stderr


@pytest.mark.parametrize("periods", ["0", "-1", "nan"])
def test_periods_must_be_positive(periods):
    result = crest("run", "builtin:sweep", "--periods", periods, "--fast")
    assert result.returncode == 2
    assert f"argument --periods: expected a number > 0, got '{periods}'" in result.stderr


def test_a_fractional_number_of_sweeps_is_refused():
    result = assert_refused_before_boot(crest("run", "builtin:sweep", "--periods", "1.5", "--fast"))
    assert "whole number" in result


def test_a_setpoint_file_refuses_a_controller_it_cannot_apply(tmp_path):
    setpoints = tmp_path / "slow.csv"
    setpoints.write_text(SLOW_SETPOINTS)
    stderr = assert_refused_before_boot(crest("run", str(setpoints), "--controller", "dahl+fb", "--fast"))
    assert "--controller does not apply to a set-point file" in stderr


@pytest.mark.parametrize("option,value", [("--articulation-deg", "45"), ("--periods", "2")])
def test_a_setpoint_file_refuses_builtin_options(tmp_path, option, value):
    setpoints = tmp_path / "slow.csv"
    setpoints.write_text(SLOW_SETPOINTS)
    stderr = assert_refused_before_boot(crest("run", str(setpoints), option, value, "--fast"))
    assert f"{option} apply only to builtin trajectories" in stderr


def test_a_builtin_refuses_an_option_it_does_not_use():
    stderr = assert_refused_before_boot(crest("run", "builtin:history", "--periods", "2", "--fast"))
    assert "--periods does not apply to builtin:history" in stderr


def test_nan_pitch_is_refused_in_the_units_the_user_typed():
    stderr = assert_refused_before_boot(crest("move", "--pitch", "nan", "--yaw", "0"))
    assert "--pitch nan: give a finite number of degrees" in stderr and "pitch_rad" not in stderr


def test_a_short_setpoint_row_names_its_line_and_column(tmp_path):
    setpoints = tmp_path / "short.csv"
    setpoints.write_text("t,tendon_cmd_1,tendon_cmd_2,tendon_cmd_3,tendon_cmd_4,insertion_cmd\n"
                         "0,0,0,0,0,22\n1,0,0\n")
    stderr = assert_refused_before_boot(crest("run", str(setpoints), "--fast"))
    assert "line 3, column 'tendon_cmd_3': the row ends before this column" in stderr
    assert "None" not in stderr


def test_fit_on_a_missing_log_says_the_log_is_missing(tmp_path):
    missing = tmp_path / "missing.csv"
    result = crest("fit", str(missing), "--out", str(tmp_path / "fitted.toml"))
    assert result.returncode == ExitCode.ERROR
    assert f"{missing}: no such file" in result.stderr and "sidecar" not in result.stderr


def test_fit_reads_its_held_out_logs_before_the_fit(tmp_path):
    """A missing --holdout log is named at once, not after minutes of fitting the training logs."""
    missing = tmp_path / "held.csv"
    result = crest("fit", str(tmp_path / "train.csv"), "--holdout", str(missing), "--out", str(tmp_path / "fitted.toml"))
    assert result.returncode == ExitCode.ERROR
    assert f"{missing}: no such file" in result.stderr and "starts fitted" not in result.stderr
    assert not (tmp_path / "fitted.toml").exists()


def test_fit_progress_has_one_prefix(monkeypatch):
    from crest.gap import log_diagnosis

    def calibrate_base(recordings, prior, *, on_fit, **settings):
        on_fit(1, 4)

    messages = []
    monkeypatch.setattr(log_diagnosis, "load_recordings", lambda paths: [])
    monkeypatch.setattr(log_diagnosis, "calibrate_base", calibrate_base)
    log_diagnosis.calibrate_logs(["train.csv"], progress=messages.append,
                                 settings=log_diagnosis.DiagnosisSettings(workers=1))
    assert messages[0] == "base model: 1/4 starts fitted"
    assert messages[1].startswith("the logs hold no drive tensions: the force scale") and len(messages) == 2


def test_blind_benchmark_counts_read_as_a_sentence():
    counts = {"single": 30, "single_below_noise": 2, "none": 6, "pair": 4, "skipped": 0, "no_result": 1}
    score = {"cases": 40, "counts": counts, "top1_single": 0.9, "top1_single_above_noise": 0.95,
             "none_clean": 1.0, "pair_exact": 0.5, "pair_any_found": 1.0,
             "shrink_error_pp": {"mean": 5.0, "median": 4.0, "within_10pp": 0.9}}
    first = format_score(score).splitlines()[0]
    assert first == "blind benchmark, 40 cases: 30 with one effect, 4 with two, 6 clean (1 without a result)"


def test_debug_works_after_the_command():
    result = crest("run", "builtin:nowhere", "--debug")
    assert result.returncode != 2, result.stderr                    # not a usage error
    assert "Traceback" in result.stderr and "unknown trajectory 'builtin:nowhere'" in result.stderr


def test_fault_and_effect_help_list_every_kind_axis_and_effect_id():
    result = crest("run", "--help")
    assert result.returncode == 0
    text = " ".join(result.stdout.split())
    for kind in FaultKind:
        assert kind.value in text
    for axis in ("tendon1", "tendon4", "insertion", "tracker"):
        assert axis in text
    for effect_id, effect in EFFECTS.items():
        assert f"{effect_id} ({', '.join(effect.param_names)})" in text
    assert "SECONDS counts from the start of the command's motion" in text


@pytest.mark.parametrize("effects,says", [("backlash,friction", "unknown effect 'friction'"), (",", "no effect given")])
def test_gap_refuses_an_effect_the_catalog_does_not_hold_before_reading_a_log(tmp_path, effects, says):
    result = crest("gap", str(tmp_path / "missing.csv"), "--holdout", str(tmp_path / "missing.csv"),
                   "--effects", effects)
    assert result.returncode == ExitCode.USAGE, result.stderr
    assert f"--effects: {says}; the catalog's effects: tendon_elasticity, backlash," in result.stderr
    assert "no such file" not in result.stderr and "Traceback" not in result.stderr


@pytest.mark.parametrize("mode", [["--blind-benchmark", "--cases", "1"], ["--real-data"]])
def test_the_whole_catalogs_scores_refuse_effects_before_any_work(tmp_path, mode):
    result = crest("gap", *mode, "--effects", "backlash", "--work-dir", str(tmp_path / "w"))
    assert result.returncode == ExitCode.ERROR, result.stderr
    assert result.stderr.strip() == ("crest: error: --effects applies to a diagnosis of given logs: --blind-benchmark, "
                                     "--real-data and --combine score the whole catalog (run with --debug for the "
                                     "traceback)")
    assert not (tmp_path / "w").exists()
