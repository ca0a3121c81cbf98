"""External point forces act through the contact-point Jacobian (seed paper II)."""
import numpy as np
import pytest

from model import DahlCatheter, ModelInputError

RELEASED_MM = [-3.0, -3.0, -3.0, -3.0]   # every tendon slack: the catheter is a free cantilever
FORCE_N = 0.005                           # deflects the tip by about 1 % of L: linear beam theory holds


def settled_tip(model, tendons_mm, moves=3):
    """The loads act on the previous sub-step's shape: repeat the move until the tip settles."""
    for _ in range(moves):
        tip = model.move_to(tendons_mm)
    return tip


@pytest.mark.parametrize("n_elements, tolerance", [(20, 0.05), (80, 0.015)])
def test_tip_force_deflects_a_released_catheter_like_a_cantilever(params, n_elements, tolerance):
    """delta = F L^3 / (3 EI), converging as N grows (moments are taken at the element bases)."""
    frictionless = params.frictionless()
    length, stiffness = frictionless.free_length_mm, frictionless.bending_stiffness_nmm2
    model = DahlCatheter(frictionless, n_elements)
    model.set_point_forces([FORCE_N, 0.0, 0.0])
    tip = settled_tip(model, RELEASED_MM)
    assert tip[0] == pytest.approx(FORCE_N * length ** 3 / (3 * stiffness), rel=tolerance)
    assert tip[1] == pytest.approx(0.0, abs=1e-9)


def test_force_at_mid_length_follows_beam_theory(params):
    """A force at a = L/2 from the base moves the tip by F a^2 (3L - a) / (6 EI), toward the force."""
    frictionless = params.frictionless()
    length, stiffness = frictionless.free_length_mm, frictionless.bending_stiffness_nmm2
    model = DahlCatheter(frictionless, 80)
    model.set_point_forces([[0.0, -FORCE_N, 0.0]], from_tip_mm=[length / 2])
    tip = settled_tip(model, RELEASED_MM)
    a = length / 2
    assert tip[1] == pytest.approx(-FORCE_N * a * a * (3 * length - a) / (6 * stiffness), rel=0.03)
    assert tip[0] == pytest.approx(0.0, abs=1e-9)


def test_held_tendons_stiffen_the_catheter_against_a_tip_force(params):
    """Tendons held at zero displacement must stretch to let the catheter bend: far less deflection."""
    released = DahlCatheter(params)
    held = DahlCatheter(params)
    for model in (released, held):
        model.set_point_forces([FORCE_N, 0.0, 0.0])
    free_deflection = settled_tip(released, RELEASED_MM)[0]
    held_deflection = settled_tip(held, [0.0, 0.0, 0.0, 0.0])[0]
    assert 0.0 < held_deflection < 0.5 * free_deflection
    assert held.tendon_tension_n[2].max() > 0.0          # the tendon on the convex side carries it


def test_axial_force_on_a_straight_catheter_does_not_bend_it(params):
    model = DahlCatheter(params)
    model.set_point_forces([0.0, 0.0, -1.0])
    tip = settled_tip(model, RELEASED_MM)
    assert np.hypot(tip[0], tip[1]) < 1e-9


def test_force_inside_the_support_tube_acts_on_the_tube(params):
    model = DahlCatheter(params)
    model.set_point_forces([FORCE_N, 0.0, 0.0], from_tip_mm=[params.free_length_mm + 1.0])
    assert np.hypot(*settled_tip(model, RELEASED_MM)[:2]) < 1e-9


def test_removing_the_force_returns_a_frictionless_catheter_to_straight(params):
    model = DahlCatheter(params.frictionless())
    model.set_point_forces([FORCE_N, FORCE_N, 0.0])
    assert np.hypot(*settled_tip(model, RELEASED_MM)[:2]) > 0.5
    model.set_point_forces(np.empty((0, 3)))
    assert np.hypot(*settled_tip(model, RELEASED_MM)[:2]) < 1e-9


@pytest.mark.parametrize("forces, distances, match", [
    ([np.nan, 0.0, 0.0], None, "finite"),
    ([FORCE_N, 0.0, 0.0], [-1.0], ">= 0"),
    ([[FORCE_N, 0.0, 0.0], [0.0, FORCE_N, 0.0]], [0.0], "one distance per force"),
])
def test_bad_point_force_raises_and_keeps_the_loads(params, forces, distances, match):
    model = DahlCatheter(params)
    model.set_point_forces([0.0, FORCE_N, 0.0])
    with pytest.raises(ModelInputError, match=match):
        model.set_point_forces(forces, from_tip_mm=distances)
    np.testing.assert_array_equal(model.point_forces_n, [[0.0, FORCE_N, 0.0]])
