"""Physical facts of the lumped Dahl catheter (issue: model, section Tests)."""
import numpy as np
import pytest

from model import ConstantCurvature, DahlCatheter
from tests.model.conftest import articulation, tip_angle_rad


@pytest.mark.parametrize("plane_deg", [0.0, 90.0, 45.0])   # pitch, yaw, diagonal
@pytest.mark.parametrize("degrees", [45.0, 90.0, 180.0, 270.0])
def test_frictionless_model_is_constant_curvature(params, degrees, plane_deg):
    frictionless = params.frictionless()
    model = DahlCatheter(frictionless)
    u = articulation(params, degrees, plane_deg)
    tip = model.move_to(u)
    length = frictionless.free_length_mm
    cc_tip = ConstantCurvature(frictionless).tip_mm(u, length)
    assert np.linalg.norm(tip - cc_tip) < 0.01 * length
    curvature = model.curvature_per_mm
    assert np.ptp(curvature) < 0.01 * curvature.mean()
    assert curvature.mean() == pytest.approx(np.deg2rad(degrees) / length, rel=0.02)


def test_pulling_tendon_one_bends_toward_plus_x(params):
    tip = DahlCatheter(params).move_to([3.0, 0.0, -3.0, 0.0])
    assert tip[0] > 10.0 and abs(tip[1]) < 1e-6


def test_friction_makes_curvature_fall_from_base_to_tip_at_90_degrees(params):
    """Paper Fig. 3.1: friction consumes tension along the catheter, so the base bends most."""
    model = DahlCatheter(params)
    model.move_to(articulation(params, 90.0))
    curvature = model.curvature_per_mm
    assert np.all(np.diff(curvature) < 0)
    assert curvature[0] > 1.3 * curvature[-1]


def test_tension_ratio_follows_capstan_law_in_steady_sliding(params):
    """With Fsc = 0 and saturated friction, T_base / T_tip = e^(mu * theta_total) (paper eq. 2)."""
    capstan_only = params.replace(fsc_n_per_mm=0.0, sigma_n_per_mm2=20.0)
    model = DahlCatheter(capstan_only)
    model.move_to(articulation(params, 90.0))
    theta_total = model.curvature_per_mm.sum() * model.free_length_mm / model.n_elements
    ratio = model.drive_tension_n[0] / model.state.tip_tension_n[0]
    assert ratio == pytest.approx(np.exp(capstan_only.mu * theta_total), rel=0.05)
    assert ratio > 1.2


def loop_area(params, mu):
    model = DahlCatheter(params.replace(mu=mu), n_elements=10)
    up = np.deg2rad(np.linspace(0.0, 150.0, 300))
    path = np.concatenate([up, up[::-1]])
    u = np.array([articulation(params, np.rad2deg(t)) for t in path])
    angle = tip_angle_rad(model.run(u))
    return abs(np.trapezoid(angle, u[:, 0]))


def test_articulation_hysteresis_loop_grows_with_mu(params):
    frictionless_area = loop_area(params.replace(fsc_n_per_mm=0.0), 0.0)
    areas = [loop_area(params, mu) for mu in (0.1, 0.2, 0.4)]
    assert frictionless_area < 1e-3
    assert areas[0] > 0.05
    assert areas[0] < areas[1] < areas[2]


def history_moves(params, start_with_zero_friction):
    """Tip displacements for +10 and -10 deg articulation moves away from 180 deg."""
    at_180 = articulation(params, 180.0)
    moves = []
    for step_deg in (10.0, -10.0):
        model = DahlCatheter(params)
        if start_with_zero_friction:     # at 180 deg on the zero crossing of every Dahl curve
            fresh = DahlCatheter(params.frictionless())
            fresh.move_to(at_180)
            model.restore(fresh.snapshot())
        else:                            # arrived from 0 deg: friction loaded in one direction
            model.move_to(at_180)
        start = model.tip_mm.copy()
        moves.append(model.move_to(articulation(params, 180.0 + step_deg)) - start)
    return moves


def test_history_fig_4_4_two_starts_respond_differently(params):
    """Paper Fig. 4.4: zero friction responds symmetrically; prior motion makes it asymmetric."""
    up_fresh, down_fresh = history_moves(params, start_with_zero_friction=True)
    up_hist, down_hist = history_moves(params, start_with_zero_friction=False)
    assert np.linalg.norm(up_fresh) == pytest.approx(np.linalg.norm(down_fresh), rel=0.05)
    assert abs(np.linalg.norm(up_hist) / np.linalg.norm(down_hist) - 1.0) > 0.2
    cosine = up_fresh @ up_hist / np.linalg.norm(up_fresh) / np.linalg.norm(up_hist)
    assert np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0))) > 10.0


def test_tips_agree_for_20_and_80_elements(params):
    u = articulation(params, 180.0)
    tip_20 = DahlCatheter(params, n_elements=20).move_to(u)
    tip_80 = DahlCatheter(params, n_elements=80).move_to(u)
    assert np.linalg.norm(tip_20 - tip_80) < 0.01 * params.free_length_mm


def test_any_n_from_four_works(params):
    tip = DahlCatheter(params, n_elements=4).move_to(articulation(params, 90.0))
    assert np.isfinite(tip).all()
    with pytest.raises(ValueError, match="n_elements"):
        DahlCatheter(params, n_elements=3)


def test_insertion_follows_geometry_and_retracted_part_carries_no_bend(params):
    """Frictionless, at fixed tendons the free part keeps the whole bend u/r at any free length."""
    frictionless = params.frictionless()
    model = DahlCatheter(frictionless)
    u = articulation(params, 180.0)
    model.move_to(u)
    for length in (60.0, 95.0, 40.0):
        tip = model.move_to(u, length)
        assert np.linalg.norm(tip - ConstantCurvature(frictionless).tip_mm(u, length)) < 0.01 * length
        bend_total = model.curvature_per_mm.sum() * length / model.n_elements
        assert bend_total == pytest.approx(np.pi, rel=0.01)
        assert np.allclose(model.backbone_mm[0], 0.0)
        assert model.free_length_mm == length


def test_friction_never_pushes_a_tendon_even_when_it_dominates(params):
    """Near-Coulomb friction (pre-sliding ~3 um) with a large interference fit (4 N over the length)
    and no pretension: the solve stays finite, friction never pushes a tendon (tension stays above
    zero but for a re-tightening tendon's tip, at most one element's constant friction below it),
    and most sub-steps converge (the rest, stick-slip reversals of near-Coulomb friction, are
    committed with the exact Dahl state; a known limit of the solver, measured at 3.7 %)."""
    sticky = params.replace(mu=0.1, fsc_n_per_mm=0.05, sigma_n_per_mm2=20.0)
    model = DahlCatheter(sticky)
    up = np.deg2rad(np.linspace(0.0, 60.0, 120))
    path = np.array([articulation(params, np.rad2deg(t)) for t in np.concatenate([up, up[::-1]])])
    tips = model.run(path)
    assert np.isfinite(tips).all()
    iterations, unconverged = model.solver_iterations
    assert unconverged <= 0.05 * iterations
    element_friction_n = sticky.fsc_n_per_mm * model.free_length_mm / model.n_elements
    assert model.tendon_tension_n.min() > -element_friction_n
    assert model.drive_tension_n.min() > -1e-3   # numerical zero
