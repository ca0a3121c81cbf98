"""The dynamic mode (seed paper I.A, Fig. 1): M b'' + C b' + K b = f by backward Euler."""
import math

import numpy as np
import pytest

from crest.bench.model_bench import SAMPLE_RATE_HZ, fast_inputs, time_step_error
from model import DahlCatheter, ModelInputError
from tests.model.conftest import articulation

CANTILEVER_MODE_1 = 1.8751 ** 4    # (beta_1 L)^4 of a clamped-free beam
SLACK_MM = np.full(4, -1.0)        # every tendon paid out: a free cantilever


def first_mode_rad_s(params, inertia_scale=1.0):
    """omega_1 = sqrt((beta_1 L)^4 EI / (rho L^4)) of the clamped-free beam [rad/s] (1 N = 1e3 kg*mm/s^2)."""
    rho_l4 = params.linear_density_kg_per_mm * params.free_length_mm ** 4
    return math.sqrt(CANTILEVER_MODE_1 * params.bending_stiffness_nmm2 * 1e3 / (inertia_scale * rho_l4))


def tip_force_step(params, n_elements=20, force_n=0.005, duration_s=0.2, dt_s=1e-4):
    """Tip x [mm] of a free cantilever after a step of a small transverse tip force at t = 0."""
    model = DahlCatheter(params, n_elements, max_time_step_s=dt_s)
    model.run(SLACK_MM[None, :], dt_s=dt_s)
    model.set_point_forces([[force_n, 0.0, 0.0]])
    return model.run(np.tile(SLACK_MM, (int(round(duration_s / dt_s)), 1)), dt_s=dt_s)[:, 0]


def articulation_path(params, peak_deg, duration_s, dt_s=0.01):
    """Sine articulation 0 -> peak_deg -> 0 in the x-z plane, tendon inputs [T, 4]."""
    angles = peak_deg * np.sin(np.linspace(0.0, np.pi, int(round(duration_s / dt_s))))
    return np.array([articulation(params, a, pretension_mm=0.02) for a in angles])


def test_slow_input_agrees_with_quasi_static_within_1_percent_of_length(params):
    """Paper I.A: driven quasi-statically, the dynamic simulation gives the quasi-static solution."""
    dynamic = params.replace(damping_time_s=0.02, inertia_scale=1.0)
    path = articulation_path(params, 150.0, duration_s=20.0)
    quasi_static_tips = DahlCatheter(params).run(path)
    dynamic_tips = DahlCatheter(dynamic).run(path)
    assert np.linalg.norm(dynamic_tips - quasi_static_tips, axis=1).max() < 0.01 * params.free_length_mm


def test_zero_masses_and_dampers_are_the_quasi_static_solver(params):
    path = articulation_path(params, 120.0, duration_s=2.0)
    off = params.replace(damping_time_s=0.0, inertia_scale=0.0)
    np.testing.assert_array_equal(DahlCatheter(off).run(path), DahlCatheter(params).run(path))


def test_quasi_static_drive_reproduces_the_quasi_static_hysteresis_loop(params):
    """Paper I.A: with quasi-static motion, friction history matches static deflection.

    The loop width (tip x at the same input on the way up and down) at every input.
    """
    dynamic = params.replace(damping_time_s=0.02, inertia_scale=1.0)
    path = articulation_path(params, 150.0, duration_s=20.0)
    half = len(path) // 2

    def loop_width_mm(tips):
        up, down = tips[:half, 0], tips[half:2 * half, 0][::-1]
        return down - up

    quasi_static = loop_width_mm(DahlCatheter(params).run(path))
    dynamic_width = loop_width_mm(DahlCatheter(dynamic).run(path))
    widest = np.abs(quasi_static).max()
    assert widest > 1.0          # the loop is there (friction)
    assert np.abs(dynamic_width - quasi_static).max() < 0.05 * widest


def test_fast_input_lags_the_quasi_static_solution(params):
    """With the dampers, a fast articulation lags the static answer and settles to it without overshoot."""
    frictionless = params.frictionless().replace(damping_time_s=0.5)
    model = DahlCatheter(frictionless, max_time_step_s=0.002)
    model.set_point_forces([[0.0, 0.0, 0.0]])
    model.run(SLACK_MM[None, :], dt_s=0.01)
    model.set_point_forces([[0.02, 0.0, 0.0]])
    tips = model.run(np.tile(SLACK_MM, (400, 1)), dt_s=0.01)[:, 0]
    static = DahlCatheter(frictionless.replace(damping_time_s=0.0))
    static.set_point_forces([[0.02, 0.0, 0.0]])
    static.move_to(SLACK_MM)
    static.move_to(SLACK_MM)   # point loads act on the last shape: a second move settles them
    final_mm = static.tip_mm[0]
    assert tips[0] < 0.1 * final_mm
    assert np.all(np.diff(tips) >= -1e-9)        # first order: monotone, no overshoot
    assert tips[-1] == pytest.approx(final_mm, rel=0.01)


def test_step_response_of_a_damped_element_matches_the_second_order_system(params):
    """A tip-force step on the free cantilever: each element is m b'' + c b' + K_b b = M(t).

    x'' + 2 zeta omega x' + omega^2 x = omega^2 x_ss with omega the first beam mode and
    zeta = tau*omega/2: overshoot exp(-pi zeta / sqrt(1 - zeta^2)) at t = pi / (omega sqrt(1 - zeta^2)).
    """
    omega = first_mode_rad_s(params)
    zeta = 0.3
    damped = params.frictionless().replace(damping_time_s=2.0 * zeta / omega, inertia_scale=1.0)
    x = tip_force_step(damped, duration_s=0.4)
    dt_s = 1e-4
    final = x[-1]
    peak = int(np.argmax(x))
    omega_d = omega * math.sqrt(1.0 - zeta ** 2)
    assert x[peak] / final - 1.0 == pytest.approx(math.exp(-math.pi * zeta / math.sqrt(1 - zeta ** 2)), abs=0.02)
    assert (peak + 1) * dt_s == pytest.approx(math.pi / omega_d, rel=0.03)


def test_step_response_without_mass_is_first_order_with_the_damping_time(params):
    """Massless dampers: x(t) = x_ss (1 - exp(-t/tau)), 63 % at t = tau, never beyond x_ss."""
    tau_s = 0.02
    x = tip_force_step(params.frictionless().replace(damping_time_s=tau_s), duration_s=0.2)
    t63 = (int(np.argmax(x >= (1 - math.exp(-1)) * x[-1])) + 1) * 1e-4
    assert t63 == pytest.approx(tau_s, rel=0.03)
    assert x.max() <= x[-1] * (1 + 1e-9)


def stored_energy_nmm(model):
    """Bending strain energy sum 1/2 K_b |b|^2 plus kinetic energy sum 1/2 m |b'|^2 [N*mm].

    K_b = EI/h, m = s_m * 1e-3 * rho L^4 / ((beta_1 L)^4 h) (CatheterParams, the dynamics section).
    """
    p = model.params
    length = model.free_length_mm
    h = length / model.n_elements
    k_b = p.bending_stiffness_nmm2 / h
    mass = p.inertia_scale * 1e-3 * p.linear_density_kg_per_mm * length ** 4 / (CANTILEVER_MODE_1 * h)
    s = model.state
    return 0.5 * k_b * np.sum(s.bend_rad ** 2) + 0.5 * mass * np.sum(s.bend_rate_rad_s ** 2)


@pytest.mark.parametrize("damping_time_s", [0.0, 0.005])
def test_released_cantilever_creates_no_energy_with_friction_off(params, damping_time_s):
    """After the tip force is removed, no step adds energy: backward Euler only dissipates."""
    p = params.frictionless().replace(damping_time_s=damping_time_s, inertia_scale=1.0)
    model = DahlCatheter(p, max_time_step_s=5e-4)
    model.set_point_forces([[0.02, 0.0, 0.0]])
    model.run(np.tile(SLACK_MM, (200, 1)), dt_s=5e-4)
    model.set_point_forces(np.empty((0, 3)))
    energies = [stored_energy_nmm(model)]
    for _ in range(300):
        model.run(SLACK_MM[None, :], dt_s=5e-4)
        energies.append(stored_energy_nmm(model))
    energies = np.array(energies)
    assert energies[0] > 0.0
    assert np.all(np.diff(energies) <= 1e-12 * energies[0])
    if damping_time_s > 0:
        assert energies[-1] < 0.5 * energies[0]


def test_dynamic_response_does_not_depend_on_the_number_of_elements(params):
    """The transient, normalised by its end value, is the same at N = 10, 20 and 40.

    (The end value itself is the static discretisation of a tip load, within 2 % from N = 20 on.)
    """
    damped = params.frictionless().replace(damping_time_s=0.01, inertia_scale=1.0)
    responses = {n: tip_force_step(damped, n_elements=n, duration_s=0.15) for n in (10, 20, 40)}
    for n in (10, 20):
        shape, reference = responses[n] / responses[n][-1], responses[40] / responses[40][-1]
        assert np.abs(shape - reference).max() < 0.02
    assert responses[20][-1] == pytest.approx(responses[40][-1], rel=0.02)


def test_fast_articulation_with_friction_does_not_depend_on_the_number_of_elements(params):
    dynamic = params.replace(damping_time_s=0.05, inertia_scale=1.0)
    path = articulation_path(params, 150.0, duration_s=1.0)
    tips = {n: DahlCatheter(dynamic, n).run(path) for n in (20, 40)}
    assert np.linalg.norm(tips[20] - tips[40], axis=1).max() < 0.01 * params.free_length_mm


def test_time_steps_converge_toward_a_fine_reference(params):
    """Backward Euler on fast inputs with a 20 ms damping time and the catheter's mass (a 13 Hz
    mode), against 0.3125 ms steps: the error falls as the step shrinks, and the default 10 ms
    (one step per 100 Hz sample) stays within the tracker's noise (0.1 mm per axis, 0.17 mm as a
    3-D RMS). Friction makes the rest state depend on how the 13 Hz mode rings down, which 10 ms
    steps do not resolve (`crest bench --only dynamic` reports the 10 ms error)."""
    dynamic = params.replace(damping_time_s=0.02, inertia_scale=1.0)
    assert DahlCatheter(dynamic).max_time_step_s == 0.01
    for path in fast_inputs(params).values():
        assert np.abs(np.diff(path, axis=0)).max() * SAMPLE_RATE_HZ > 15.0    # fast: > 15 mm/s of pull
    errors_mm = time_step_error(dynamic, (0.01, 0.0025, 0.000625))
    for name in fast_inputs(params):
        assert errors_mm[0.01][name] > errors_mm[0.0025][name] > errors_mm[0.000625][name]
        assert errors_mm[0.01][name] < 0.12


@pytest.mark.parametrize("tendons, dt_s", [
    (np.array([[math.nan, 0.0, 0.0, 0.0]]), 0.01),
    (np.array([[math.inf, 0.0, 0.0, 0.0]]), 0.01),
    (np.array([[1.0, 0.0, -1.0, 0.0]]), math.nan),
    (np.array([[1.0, 0.0, -1.0, 0.0]]), math.inf),
    (np.array([[1.0, 0.0, -1.0, 0.0]]), 0.0),
    (np.array([[1.0, 0.0, -1.0, 0.0]]), -0.01),
    (np.array([[1.0, 0.0, -1.0, 0.0]]), 60.0),
])
def test_bad_input_raises_and_leaves_the_dynamic_state_unchanged(params, tendons, dt_s):
    model = DahlCatheter(params.replace(damping_time_s=0.02, inertia_scale=1.0))
    model.run(articulation_path(params, 90.0, duration_s=0.3))    # mid-motion: the bends move
    before = model.snapshot()
    assert np.abs(before.bend_rate_rad_s).max() > 0.0
    with pytest.raises(ModelInputError):
        model.run(tendons, dt_s=dt_s)
    after = model.snapshot()
    for name in ("bend_rad", "bend_rate_rad_s", "friction_n", "tension_n", "points_mm", "applied_tendon_mm"):
        np.testing.assert_array_equal(getattr(after, name), getattr(before, name))


@pytest.mark.parametrize("field", ["damping_time_s", "inertia_scale"])
def test_negative_dynamics_parameters_are_refused(params, field):
    with pytest.raises(ValueError, match=field):
        params.replace(**{field: -0.01})
