"""The diagnosis says when the held-out logs go where the training logs never went (model/gap/coverage.py):
there the calibration extrapolates, and its error is no evidence of a missing effect. The standard
excitations stay inside the training's range."""
import json

import numpy as np
import pytest

from control.excitation import holdout_trajectory, training_trajectory
from crest.config import load_testbed_config
from crest.experiment.workspace_from_config import limits_for, workspace_for
from model import CatheterParams
from model.gap.coverage import coverage_lines
from model.gap.recording import Recording
from tests.cli.cli_runner import crest

OFFSET_MM = 2.5      # tendon offset: a differential pull d on one pair bends theta = d/2 / r rad


def sweep(name: str, top_deg: float, insertion_mm: tuple[float, float], n: int = 200) -> Recording:
    """A pull of tendon pair 1/3 from straight to `top_deg` of articulation, over a free length ramp."""
    pull_mm = np.radians(np.linspace(0.0, top_deg, n)) * OFFSET_MM     # u1 - u3 = 2 r theta, split in two
    tendon_mm = np.column_stack([pull_mm, np.zeros(n), -pull_mm, np.zeros(n)])
    return Recording(name, np.arange(n) * 0.1, tendon_mm, np.linspace(*insertion_mm, n), np.zeros((n, 3)), None,
                     100.0, OFFSET_MM, None)


def test_held_out_samples_inside_the_training_range_say_nothing():
    assert coverage_lines([sweep("train", 100.0, (50.0, 90.0))], [sweep("held", 105.0, (48.0, 92.0))],
                          [0.0] * 4) == []


def test_a_held_out_log_that_bends_further_is_named_with_its_share_and_range():
    (line,) = coverage_lines([sweep("train", 40.0, (60.0, 60.0))], [sweep("held", 120.0, (60.0, 60.0))], [0.0] * 4)
    # theta > 50 deg on the held-out ramp 0..120 deg: samples 84..199 of 200, 58%
    assert line.startswith("the held-out logs bend further than the training logs: 58% of their samples")
    assert "(40 deg; up to 120 deg)" in line


@pytest.mark.parametrize("held_mm,share", [((60.0, 100.0), "50%"), ((20.0, 60.0), "75%")])
def test_free_lengths_outside_the_training_range_are_named(held_mm, share):
    (line,) = coverage_lines([sweep("train", 90.0, (55.0, 75.0))], [sweep("held", 90.0, held_mm)], [0.0] * 4)
    assert line.startswith(f"the held-out logs reach free lengths the training logs did not: {share}")
    assert "outside the training's 55-75 mm" in line


def test_the_standard_excitations_stay_inside_the_training_range():
    params, config = CatheterParams.from_toml(), load_testbed_config()
    workspace, limits = workspace_for(config, params), limits_for(config)
    for short in (True, False):
        recordings = []
        for name, make in (("train", training_trajectory), ("held", holdout_trajectory)):
            path = make(workspace, limits, 0.1, short=short)
            n = len(path.t_s)
            recordings.append(Recording(name, path.t_s, path.tendon_mm, path.insertion_mm, np.zeros((n, 3)), None,
                                        100.0, params.tendon_offset_mm, None))
        assert coverage_lines(recordings[:1], recordings[1:], [0.0] * 4) == [], f"short={short}"


def test_crest_gap_notes_a_held_out_log_that_bends_further_than_its_training_log(tmp_path):
    """Through the CLI, on logs recorded on the virtual testbed: a training run that bends about 11 deg and
    a held-out run that bends about 34 deg, at the same free length."""
    logs = []
    for name, pull_mm in (("train", 0.5), ("held", 1.5)):
        setpoints, log = tmp_path / f"{name}_setpoints.csv", tmp_path / f"{name}.csv"
        setpoints.write_text("t,tendon_cmd_1,tendon_cmd_2,tendon_cmd_3,tendon_cmd_4,insertion_cmd\n"
                             f"0,0,0,0,0,60\n4,{pull_mm},0,{-pull_mm},0,60\n8,0,0,0,0,60\n")
        recorded = crest("run", str(setpoints), "--fast", "--record", str(log))
        assert recorded.returncode == 0, recorded.stderr
        logs.append(log)
    result = crest("gap", str(logs[0]), "--holdout", str(logs[1]), "--effects", "backlash", "--json",
                   str(tmp_path / "gap.json"), timeout_s=1200.0)
    assert result.returncode == 0, result.stderr
    (note,) = [line for line in result.stdout.splitlines() if line.startswith("note: ")]
    assert note.startswith("note: the held-out logs bend further than the training logs: ")
    assert "where the calibration extrapolates" in note
    assert json.loads((tmp_path / "gap.json").read_text())["coverage"] == [note.removeprefix("note: ")]
