"""Calibrated constant curvature, the reference of the real-data table: it recovers the geometry of
constant-curvature data, and the frictionless Dahl model is constant curvature."""
import numpy as np

from model import CatheterParams, DahlCatheter
from model.gap.cc_calibration import calibrate_constant_curvature, cc_tips_mm
from model.gap.recording import Recording


def _recording(tendon_mm: np.ndarray, tip_mm: np.ndarray, nominal_offset_mm: float) -> Recording:
    n = len(tendon_mm)
    return Recording("cc", np.arange(n) * 0.1, tendon_mm, np.full(n, 60.0), tip_mm, None, 60.0,
                     nominal_offset_mm, 6.0)


def _sweep_mm(samples: int = 200, amplitude_mm: float = 2.0) -> np.ndarray:
    """Antagonistic pulls around the bending circle at a growing amplitude."""
    phase = np.linspace(0.0, 6 * np.pi, samples)
    a = amplitude_mm * np.linspace(0.2, 1.0, samples)
    return np.column_stack([a * np.cos(phase), a * np.sin(phase), -a * np.cos(phase), -a * np.sin(phase)])


def test_recovers_the_moment_arm_and_the_tendon_zeros_of_constant_curvature_data():
    tendons = _sweep_mm()
    truth = np.array([0.3, -0.2, -0.3, 0.2])
    placeholder = _recording(tendons, np.zeros((len(tendons), 3)), 2.5)
    noise = np.random.default_rng(0).normal(0.0, 0.05, (len(tendons), 3))
    recording = _recording(tendons, cc_tips_mm(2.2, truth, placeholder) + noise, 2.5)
    fit = calibrate_constant_curvature([recording], CatheterParams.from_toml())
    assert abs(fit.tendon_offset_mm - 2.2) < 0.01
    assert np.allclose(fit.zero_offsets_mm, truth, atol=0.01)
    assert fit.train_rmse_mm < 0.1 and not fit.at_bound        # the noise, sqrt(3) * 0.05 mm


def test_frictionless_dahl_tips_are_fitted_by_constant_curvature_to_the_micrometre():
    """Without friction the lumped model bends as one arc: its tips are constant-curvature tips of the
    nominal geometry, so the calibration keeps the nominal arm and zero zeros."""
    params = CatheterParams.from_toml().replace(mu=0.0, fsc_n_per_mm=0.0)
    tendons = _sweep_mm(80, 1.5) + 0.05              # a small common pretension: no slack tendon
    tips = DahlCatheter(params, 20).run(tendons, np.full(len(tendons), params.free_length_mm))
    recording = Recording("dahl", np.arange(len(tendons)) * 0.1, tendons, np.full(len(tendons), params.free_length_mm),
                          tips, None, params.free_length_mm, params.tendon_offset_mm, params.outer_diameter_mm)
    fit = calibrate_constant_curvature([recording], params)
    assert fit.train_rmse_mm < 0.05
    assert abs(fit.tendon_offset_mm - params.tendon_offset_mm) < 0.02 * params.tendon_offset_mm
