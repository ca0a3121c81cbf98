"""The modified Dahl element (paper eq. 1) and the capstan law (eq. 2-3)."""
import math

import numpy as np
import pytest

from model.dahl_friction import capstan_gain, dahl_update, dahl_update_with_slopes


def euler_dahl(force, dx, fs, sigma, alpha, steps=200000):
    """Reference: eq. 1 integrated with many tiny explicit steps."""
    h = dx / steps
    d = math.copysign(1.0, dx)
    for _ in range(steps):
        force += h * sigma * max(1.0 - force / fs * d, 0.0) ** alpha
    return force


@pytest.mark.parametrize("alpha", [1.0, 0.6, 1.8])
@pytest.mark.parametrize("f0,dx", [(0.0, 0.05), (0.2, -0.03), (-0.35, 0.2)])
def test_exact_update_matches_fine_integration_of_eq1(alpha, f0, dx):
    assert dahl_update(f0, dx, 0.4, 5.0, alpha) == pytest.approx(euler_dahl(f0, dx, 0.4, 5.0, alpha), abs=1e-5)


def test_force_saturates_at_fs_and_reverses_to_minus_fs():
    fs = 0.5
    forward = dahl_update(0.0, 10.0, fs, 4.0, 1.0)
    assert forward == pytest.approx(fs, rel=1e-9)
    assert dahl_update(forward, -10.0, fs, 4.0, 1.0) == pytest.approx(-fs, rel=1e-9)


def test_initial_slope_is_sigma():
    force, slope, _ = dahl_update_with_slopes(0.0, 1e-9, 0.5, 4.0, 1.0)
    assert slope == pytest.approx(4.0, rel=1e-6)
    assert force == pytest.approx(4e-9, rel=1e-6)


def test_no_sliding_no_change():
    assert dahl_update(0.3, 0.0, 0.5, 4.0, 1.0) == 0.3


def test_capstan_gain_gives_exponential_tension_ratio():
    """Fsv = 2 T_avg tanh(mu theta/2) is exactly T_left - T_right with T_left/T_right = e^(mu theta)."""
    mu, theta, t_right = 0.3, 1.2, 5.0
    t_left = t_right * math.exp(mu * theta)
    assert capstan_gain(mu, theta) * 0.5 * (t_left + t_right) == pytest.approx(t_left - t_right, rel=1e-12)


def test_slopes_match_finite_differences():
    eps = 1e-7
    for f0, dx, fs, alpha in [(0.1, 0.01, 0.5, 1.0), (-0.3, 0.05, 0.4, 0.7), (0.2, -0.03, 0.6, 1.5)]:
        _, d_dx, d_fs = dahl_update_with_slopes(f0, dx, fs, 4.0, alpha)
        num_dx = (dahl_update(f0, dx + eps, fs, 4.0, alpha) - dahl_update(f0, dx - eps, fs, 4.0, alpha)) / (2 * eps)
        num_fs = (dahl_update(f0, dx, fs + eps, 4.0, alpha) - dahl_update(f0, dx, fs - eps, 4.0, alpha)) / (2 * eps)
        assert d_dx == pytest.approx(num_dx, rel=1e-5)
        assert d_fs == pytest.approx(num_fs, rel=1e-5, abs=1e-9)
        assert np.isfinite([d_dx, d_fs]).all()
