"""The rod plant's own dynamics: a Kelvin-Voigt shaft, EI (kappa - kappa_rest + tau dkappa/dt)."""
from __future__ import annotations

import numpy as np
import pytest

from rod_scenarios import DT_S, FREE_LENGTH_MM, description, pull, ramp
from sim_backend.plant.rod import RodDescriptionError, RodPlant

TAU_S = 0.05


def _frictionless(damping_time_s: float) -> RodPlant:
    return RodPlant(description(mu=0.0, friction_n_per_mm=0.0, grid_nodes=101, damping_time_s=damping_time_s))


def test_a_released_rod_relaxes_by_backward_euler_with_its_damping_time():
    """Both tendons slack, no friction: tau kappa' = -kappa, so each 10 ms step divides the bend by
    1 + dt/tau (backward Euler), and the bend follows exp(-t/tau) to within that integrator's error."""
    plant = _frictionless(TAU_S)
    for u in np.linspace(0.0, 2.0, 50):          # slow: the bend settles at each step
        pull(plant, u)
    for _ in range(100):
        pull(plant, 2.0)
    bends = []
    for _ in range(10):
        plant.step(DT_S, [-5.0, 0.0, -5.0, 0.0], FREE_LENGTH_MM)     # every tendon paid out: slack
        bends.append(np.linalg.norm(plant.kappa_per_mm.mean(axis=0)))
    assert np.all(plant.drive_tension_n == 0.0)
    ratios = np.array(bends[1:]) / np.array(bends[:-1])
    np.testing.assert_allclose(ratios, 1.0 / (1.0 + DT_S / TAU_S), rtol=1e-6)
    assert bends[-1] / bends[0] == pytest.approx(np.exp(-9 * DT_S / TAU_S), rel=0.3)


def test_a_held_pull_settles_to_the_quasi_static_shape():
    damped, quasi_static = _frictionless(TAU_S), _frictionless(0.0)
    fast = [(pull(damped, u)[0], pull(quasi_static, u)[0]) for u in np.linspace(0.0, 3.0, 10)]
    assert max(np.linalg.norm(a - b) for a, b in fast) > 0.5       # a 30 mm/s pull lags
    for _ in range(int(20 * TAU_S / DT_S)):
        tip, _ = pull(damped, 3.0)
    np.testing.assert_allclose(tip, pull(quasi_static, 3.0)[0], atol=1e-3)


def test_a_slow_input_agrees_with_the_quasi_static_rod_within_1_percent_of_length():
    damped, quasi_static = RodPlant(description(damping_time_s=TAU_S)), RodPlant(description())
    path = np.concatenate([np.linspace(0.0, 4.0, 400), np.linspace(4.0, -1.0, 500)])     # 0.1 mm/s... 1 mm/s
    errors = [np.linalg.norm(pull(damped, u)[0] - pull(quasi_static, u)[0]) for u in path]
    assert max(errors) < 0.01 * FREE_LENGTH_MM


def test_damping_tension_rises_with_pull_speed():
    """The damper resists bending: the same pull takes more tension when it is made faster."""
    slow, fast = RodPlant(description(damping_time_s=TAU_S)), RodPlant(description(damping_time_s=TAU_S))
    slow_tension = ramp(slow, 0.0, 3.0, steps=300)[-1][1][0]
    fast_tension = ramp(fast, 0.0, 3.0, steps=10)[-1][1][0]
    assert fast_tension > 1.05 * slow_tension


def test_a_negative_damping_time_is_refused():
    with pytest.raises(RodDescriptionError, match="damping_time_s"):
        description(damping_time_s=-0.01)
