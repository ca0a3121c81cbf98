"""The standard excitation (issue 6, `crest excite`): every primitive, inside the testbed's limits,
different trajectories for training and held-out."""
import tomllib
from pathlib import Path

import numpy as np
import pytest

from control.excitation import ExcitationGeometry, holdout_trajectory, training_trajectory
from model import CatheterParams

TESTBED = tomllib.loads((Path(__file__).resolve().parents[2] / "configs" / "testbed.toml").read_text())


@pytest.fixture(scope="module")
def geometry():
    return ExcitationGeometry.from_params(CatheterParams.from_toml())


@pytest.mark.parametrize("make", [training_trajectory, holdout_trajectory])
@pytest.mark.parametrize("short", [False, True])
def test_trajectory_holds_every_primitive_within_the_axis_limits(geometry, make, short):
    trajectory = make(geometry, 100.0, short=short)
    labels = " | ".join(s.label for s in trajectory.segments)
    for primitive in ("static hold", "sweep", "minor loops", "insertion change", "circle"):
        assert primitive in labels
    tendon = TESTBED["axis_defaults"]["tendon"]
    insertion = TESTBED["axis_defaults"]["insertion"]
    dt = trajectory.t_s[1] - trajectory.t_s[0]
    assert np.abs(np.diff(trajectory.tendon_mm, axis=0)).max() / dt <= tendon["max_velocity_mm_s"]
    assert np.abs(np.diff(trajectory.insertion_mm)).max() / dt <= insertion["max_velocity_mm_s"]
    low, high = tendon["soft_limits_mm"]
    assert low <= trajectory.tendon_mm.min() and trajectory.tendon_mm.max() <= high
    low, high = insertion["soft_limits_mm"]
    assert low <= trajectory.insertion_mm.min() and trajectory.insertion_mm.max() <= high
    # antagonistic pairs from the constant-curvature inverse: u1 + u3 = u2 + u4 = 2 * pretension
    pair_sums = trajectory.tendon_mm[:, :2] + trajectory.tendon_mm[:, 2:]
    assert np.allclose(pair_sums, 2 * geometry.pretension_mm)


def test_held_out_trajectory_differs_from_training(geometry):
    train = {s.label for s in training_trajectory(geometry).segments if "sweep" in s.label or "circle" in s.label}
    held = {s.label for s in holdout_trajectory(geometry).segments if "sweep" in s.label or "circle" in s.label}
    assert train and held and not train & held


def test_repeated_trajectory_lasts_long_enough(geometry):
    trajectory = training_trajectory(geometry, 10.0, short=True).repeated(600.0)
    assert trajectory.duration_s >= 590.0
    assert np.all(np.diff(trajectory.t_s) > 0)
