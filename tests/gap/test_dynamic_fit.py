"""`crest fit` on fast logs: the dynamic mode's damping time comes back from a noiseless fast log, and
only fast logs switch the dynamic fit on (issue 16)."""
import numpy as np
import pytest

from control import MotionLimits, Workspace
from control.excitation import training_trajectory
from model import CatheterParams, DahlCatheter, tendons_from_articulation
from model.gap.calibration import calibrate, is_fast
from model.gap.recording import Recording
from model.gap.simulation import Resolution

RATE_HZ = 20.0
RESOLUTION = Resolution(n_elements=6, fit_rate_hz=RATE_HZ)


def fast_recording(params: CatheterParams) -> Recording:
    """A noiseless 8 s log of a 1.5 Hz, 30-90 deg articulation (tendon 1 up to 12 mm/s), at RATE_HZ."""
    t = np.arange(0.0, 8.0, 1.0 / RATE_HZ)
    theta = np.radians(30.0 + 60.0 * (1.0 - np.cos(2.0 * np.pi * 1.5 * t)) / 2.0)
    tendons = np.array([tendons_from_articulation(a, 0.3, params.tendon_offset_mm, 0.02) for a in theta])
    insertion = np.full(len(t), params.free_length_mm)
    model = DahlCatheter(params, RESOLUTION.n_elements, max_tendon_step_mm=RESOLUTION.max_tendon_step_mm,
                         max_insertion_step_mm=RESOLUTION.max_insertion_step_mm)
    tips = model.run(tendons, insertion, 1.0 / RATE_HZ)
    return Recording("fast", t, tendons, insertion, tips, None, params.max_free_length_mm, params.tendon_offset_mm,
                     params.outer_diameter_mm)


def test_damping_time_comes_back_from_a_noiseless_fast_log():
    prior = CatheterParams.from_toml()
    truth = prior.replace(damping_time_s=0.06, inertia_scale=1.0)
    recording = fast_recording(truth)
    start = prior.replace(damping_time_s=0.02, inertia_scale=1.0)
    before = calibrate([recording], start, fit_base=False, fit_dynamics=False, resolution=RESOLUTION,
                       max_iterations=1, restarts=0)
    fit = calibrate([recording], start, fit_base=False, fit_dynamics=True, resolution=RESOLUTION,
                    max_iterations=20)
    assert fit.names == ("damping_time_s", "inertia_scale")
    assert fit.params.damping_time_s == pytest.approx(0.06, rel=0.2)
    assert fit.train_rmse_mm < 0.3 * before.train_rmse_mm


def test_only_fast_logs_switch_the_dynamic_fit_on():
    params = CatheterParams.from_toml()
    assert is_fast([fast_recording(params)])
    held = fast_recording(params)
    steps = Recording("steps", held.t_s, np.repeat(held.tendon_mm[::8], 8, axis=0), held.insertion_mm, held.tip_mm,
                      None, params.max_free_length_mm, params.tendon_offset_mm, params.outer_diameter_mm)
    assert is_fast([steps])
    slow = training_trajectory(Workspace.from_params(params, pretension_mm=0.02), MotionLimits(), 0.1, short=True)
    recording = Recording("slow", slow.t_s, slow.tendon_mm, slow.insertion_mm, np.zeros((len(slow.t_s), 3)), None,
                          params.max_free_length_mm, params.tendon_offset_mm, params.outer_diameter_mm)
    assert not is_fast([recording])
