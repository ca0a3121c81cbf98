"""The rod family through the CLI, as a user runs it: `--plant-config configs/rod_plant.toml`."""
from __future__ import annotations

from tests.cli.cli_runner import crest
from crest.exit_codes import ExitCode


def test_a_sweep_on_the_rod_plant_runs_to_the_end(tmp_path):
    result = crest("run", "builtin:sweep", "--articulation-deg", "90", "--fast", "--plant-config",
                   "configs/rod_plant.toml", "--effect", "stiffness_step:stiffness_ratio=0.7", "--record",
                   str(tmp_path / "sweep.csv"))
    assert result.returncode == 0, result.stderr
    assert "RMS tip error" in result.stdout
    assert (tmp_path / "sweep.csv").exists()


def test_a_dahl_effect_name_on_the_rod_plant_is_refused_before_anything_moves(tmp_path):
    result = crest("run", "builtin:sweep", "--fast", "--plant-config", "configs/rod_plant.toml",
                   "--effect", "backlash:width_mm=0.4", "--record", str(tmp_path / "sweep.csv"))
    assert result.returncode != 0 and result.returncode != ExitCode.OK
    assert "effect 'backlash' has no parameter 'width_mm'; its parameters: gear_play_mm" in result.stderr
    assert not (tmp_path / "sweep.csv").exists()
