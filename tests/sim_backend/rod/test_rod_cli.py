"""The rod family through the CLI, as a user runs it: `--plant-config configs/rod_plant.toml`."""
from __future__ import annotations

import json

from tests.cli.cli_runner import crest
from crest.exit_codes import ExitCode


def test_a_sweep_on_the_rod_plant_runs_to_the_end(tmp_path):
    result = crest("run", "builtin:sweep", "--articulation-deg", "90", "--fast", "--plant-config",
                   "configs/rod_plant.toml", "--effect", "stiffness_step:stiffness_ratio=0.7", "--record",
                   str(tmp_path / "sweep.csv"))
    assert result.returncode == 0, result.stderr
    assert "RMS tip error" in result.stdout
    # the log says which plant it was measured on, and that results on it are out of family
    plant = json.loads((tmp_path / "sweep.json").read_text())["plant"]
    assert plant.startswith("rod family") and "with stiffness_step" in plant and "out of family" in plant


def test_a_dahl_effect_name_on_the_rod_plant_is_refused_before_anything_moves(tmp_path):
    result = crest("run", "builtin:sweep", "--fast", "--plant-config", "configs/rod_plant.toml",
                   "--effect", "backlash:width_mm=0.4", "--record", str(tmp_path / "sweep.csv"))
    assert result.returncode != 0 and result.returncode != ExitCode.OK
    assert "effect 'backlash' has no parameter 'width_mm'; its parameters: gear_play_mm" in result.stderr
    assert not (tmp_path / "sweep.csv").exists()


def test_a_recording_in_simulated_time_has_the_same_rows_in_one_process_or_two(tmp_path):
    """The tracker samples the rod's tip once the plant has stepped for the SYNC the drives just
    answered, so no row depends on which thread ran first (before, a few tips per run differed by
    up to 0.3 mm between two runs of this command)."""
    logs = []
    for mode in ("in-process", "process"):
        logs.append(tmp_path / f"{mode}.csv")
        result = crest("run", "builtin:circle", "--periods", "0.5", "--fast", "--plant-config", "configs/rod_plant.toml",
                       "--record", str(logs[-1]), env={"CREST_VIRTUAL_TESTBED": mode})
        assert result.returncode == ExitCode.OK, result.stderr
    assert logs[0].read_bytes() == logs[1].read_bytes()
