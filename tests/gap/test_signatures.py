"""Residual signatures (issue 6, step 2): noise floor and dead band after reversals."""
import numpy as np
import pytest

from control import MotionLimits, Workspace
from control.excitation import training_trajectory
from model import CatheterParams, DahlCatheter
from model.effects import combined_terms
from model.gap.noise import tracker_noise_mm
from model.gap.recording import Recording
from model.gap.signatures import _dead_band

PRETENSION_MM = 0.02


def recording(t, tendon, tip, insertion=80.0):
    return Recording("r", t, tendon, np.full(len(t), insertion), tip, None, 100.0, 2.5, 6.0)


def test_noise_floor_from_static_holds_is_the_tracker_noise():
    rng = np.random.default_rng(0)
    t = np.arange(0, 30.0, 0.01)
    tendon = np.zeros((len(t), 4))
    tip = np.array([0.0, 0.0, 80.0]) + rng.normal(0.0, 0.15, (len(t), 3))
    assert tracker_noise_mm([recording(t, tendon, tip)]) == pytest.approx(0.15, rel=0.1)


def test_static_poses_of_a_repeated_sweep_tell_the_noise_from_the_second_repetition_on():
    """Poses one per second (too slow for the moving estimate, never held), the sweep run four times:
    a pose of a later run is reached along the same path as the run before, so the repeat
    differences are noise. The first run starts from rest (a transient of 2 mm here), which the
    estimate leaves out."""
    rng = np.random.default_rng(1)
    steps, runs = 64, 4
    phase = np.tile(2 * np.pi * np.arange(steps) / steps, runs)
    tendon = 1.5 * np.column_stack([np.cos(phase), np.sin(phase), -np.cos(phase), -np.sin(phase)])
    t = np.arange(len(phase), dtype=float)
    true_tip = np.column_stack([20 * np.cos(phase), 20 * np.sin(phase), np.full(len(phase), 70.0)])
    true_tip[:steps, 0] += 2.0 * np.exp(-np.arange(steps) / 10.0)          # the first run's transient
    tip = true_tip + rng.normal(0.0, 0.2, true_tip.shape)
    assert tracker_noise_mm([recording(t, tendon, tip)]) == pytest.approx(0.2, rel=0.15)
    assert tracker_noise_mm([recording(t[:steps], tendon[:steps], tip[:steps])]) is None   # one run: no estimate


def test_play_in_the_drive_train_shows_as_a_dead_band_of_its_width():
    """With backlash w the tip does not move for about w of tendon travel after each reversal."""
    params = CatheterParams.from_toml()
    trajectory = training_trajectory(Workspace.from_params(params, pretension_mm=PRETENSION_MM), MotionLimits(), 0.05,
                                     short=True)
    tips = {}
    for width_mm in (0.0, 0.6):
        model = DahlCatheter(params, 6, combined_terms({"backlash": (width_mm,)}))
        tips[width_mm] = model.run(trajectory.tendon_mm, trajectory.insertion_mm, 0.05)
    measured = recording(trajectory.t_s, trajectory.tendon_mm, tips[0.6])
    band = _dead_band([measured], [tips[0.0]], (0.0, 0.0, 0.0, 0.0), None)
    assert band["reversals"] >= 5
    assert band["excess_mm"] == pytest.approx(0.6, abs=0.2)
    assert band["model_mm"] < 0.15
