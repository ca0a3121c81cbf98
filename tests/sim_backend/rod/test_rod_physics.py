"""Physics of the rod plant, checked against closed-form rod and capstan theory."""
from __future__ import annotations

import numpy as np

from rod_scenarios import FREE_LENGTH_MM, description, pull, ramp
from sim_backend.plant.rod import RodPlant


def _frictionless(**changes) -> RodPlant:
    return RodPlant(description(mu=0.0, friction_n_per_mm=0.0, grid_nodes=101, **changes))


def _single_tendon_tension_n(d, pull_mm: float, drive_compliance_mm_per_n: float) -> float:
    """Frictionless, one tendon in a planar bend: the pull is taken up by the drive line, the
    tendon's stretch, the shaft's compression and the lumen's shortening r*theta = r^2 T L / EI:
        u = T (c_d + L/EA_t + L/EA + r^2 L / EI)"""
    length = FREE_LENGTH_MM
    return pull_mm / (drive_compliance_mm_per_n + length / d.tendon_axial_stiffness_n + length / d.axial_stiffness_n
                      + d.tendon_offset_mm ** 2 * length / d.bending_stiffness_nmm2)


def test_frictionless_rod_bends_on_the_constant_curvature_arc():
    # Without friction the tension is the same all along, so the curvature T r / EI is too; the
    # backbone is integrated as exact arcs, so the tip must lie on the arc of the same bend
    # angle up to the solver's tolerance (1e-7 mm in the tendon compatibility): 1e-6 mm.
    plant = _frictionless()
    d = plant.description
    tip, tension = ramp(plant, 0.0, 5.0, steps=20)[-1]
    expected_n = _single_tendon_tension_n(d, 5.0, d.drive_compliance_mm_per_n)
    assert tension[0] == np.float64(tension[0]) and abs(tension[0] - expected_n) < 1e-5 * expected_n
    assert np.all(tension[1:] == 0.0)          # tendon 3 is slack, 2 and 4 lie on the neutral plane
    assert np.allclose(plant.tension_n[:, 0], tension[0], rtol=1e-12)
    kappa = tension[0] * d.tendon_offset_mm / d.bending_stiffness_nmm2
    arc_mm = FREE_LENGTH_MM * (1.0 - tension[0] / d.axial_stiffness_n)   # the tendon compresses the shaft
    theta = kappa * FREE_LENGTH_MM
    assert np.degrees(theta) > 120.0
    arc_tip = np.array([(1.0 - np.cos(theta)) / kappa, 0.0, np.sin(theta) / kappa]) * arc_mm / FREE_LENGTH_MM
    assert np.linalg.norm(tip - arc_tip) < 1e-6


def test_capstan_ratio_holds_in_steady_sliding():
    # Pulled from rest, the whole tendon slides toward the drive: T(L)/T(0) = exp(-mu theta),
    # theta the total bend from the computed shape (planar: the angle of the tip tangent).
    # The walk takes each segment's wrap from its mean curvature after one correction; 0.5 %.
    plant = RodPlant(description(friction_n_per_mm=0.0))
    ramp(plant, 0.0, 5.5, steps=60)
    tangent = plant.rotation[-1][:, 2]
    theta = np.arctan2(tangent[0], tangent[2])
    assert np.degrees(theta) > 100.0
    ratio = plant.tension_n[-1, 0] / plant.tension_n[0, 0]
    expected = np.exp(-plant.description.mu * theta)
    assert abs(ratio - expected) < 0.005 * expected
    assert np.all(np.diff(plant.tension_n[:, 0]) < 0.0)   # tension falls toward the tip all along


def test_pull_release_loop_has_hysteresis():
    # Friction with memory: at the same drive input the tip is elsewhere on the way back, and
    # the drive feels less tension. With nearly inextensible tendons the total bend angle is
    # held by the pull (r theta ~ u); what friction changes is where along the shaft the bend
    # sits: near the base on the way up (tension falls toward the tip), near the tip on the way
    # back (the distal tension is held while the proximal tension drops).
    plant = RodPlant()
    tip_up, tension_up = ramp(plant, 0.0, 3.0, steps=61)[-1]
    kappa_up = plant.kappa_per_mm[:, 1].copy()
    ramp(plant, 3.0, 6.0, steps=61)
    tip_down, tension_down = ramp(plant, 6.0, 3.0, steps=61)[-1]
    kappa_down = plant.kappa_per_mm[:, 1].copy()
    assert np.linalg.norm(tip_down - tip_up) > 3.0
    assert tension_down[0] < tension_up[0] - 1.0
    assert kappa_up[0] > 1.2 * kappa_up[-1]
    assert kappa_down[-1] > 1.2 * kappa_down[0]


def test_tip_converges_under_grid_refinement():
    # Same pull-and-release history on grids of M, 2M, 4M, 8M nodes: the differences shrink.
    tips = []
    for nodes in (50, 100, 200, 400):
        plant = RodPlant(description(grid_nodes=nodes))
        ramp(plant, 0.0, 5.0, steps=50)
        tips.append(ramp(plant, 5.0, 2.5, steps=25)[-1][0])
    steps = [np.linalg.norm(b - a) for a, b in zip(tips, tips[1:])]
    assert steps[0] > steps[1] > steps[2]
    assert steps[2] < 0.1


def test_drive_line_compliance_lowers_the_tension_for_the_same_pull():
    # u = T (c_d + ...): a softer drive line takes more of the pull as stretch.
    stiff, soft = _frictionless(), _frictionless(effects={"tendon_elasticity": {"extra_compliance_mm_per_n": 0.05}})
    d = stiff.description
    _, tension_stiff = ramp(stiff, 0.0, 4.0, steps=10)[-1]
    _, tension_soft = ramp(soft, 0.0, 4.0, steps=10)[-1]
    assert abs(tension_stiff[0] - _single_tendon_tension_n(d, 4.0, 0.01)) < 1e-4
    assert abs(tension_soft[0] - _single_tendon_tension_n(d, 4.0, 0.06)) < 1e-4
    assert tension_soft[0] < tension_stiff[0] - 0.5


def test_a_tendon_cannot_push():
    plant = RodPlant()
    tip, tension = plant.step(0.01, [-3.0, -3.0, -3.0, -3.0], FREE_LENGTH_MM)
    assert np.all(tension == 0.0)
    assert np.allclose(tip, [0.0, 0.0, FREE_LENGTH_MM], atol=1e-9)


def test_insertion_moves_the_tip_along_the_tube_axis():
    plant = RodPlant()
    for length in (20.0, 55.0, 100.0):
        tip, _ = pull(plant, 0.0, length)
        assert np.allclose(tip, [0.0, 0.0, length], atol=1e-9)


def test_a_sudden_jump_with_rate_friction_on_a_moving_free_length_is_solved():
    # Once stalled the Newton solver (a step whose every fraction raised |g| at a friction kink):
    # a circle whose yaw tendons jump by 3 mm in one step at 1 s, the free length moving.
    effects = {"rate_friction": {"mu_rate_s_per_mm": 0.0673}, "lumen_offset_drift": {"tip_offset_change_mm": 0.306}}
    plant = RodPlant(description(effects=effects))
    t = np.arange(110) * 0.01
    amp = 4.8432 / np.sin(2 * np.pi * 1.02 / 3)
    pitch, yaw = amp * np.sin(2 * np.pi * t / 3), amp * np.cos(2 * np.pi * t / 3) * (t > 1)
    length = 60 + 25 * np.sin(2 * np.pi * t / 5)
    for k in range(len(t)):
        tip, tension = plant.step(0.01, [pitch[k], yaw[k], -pitch[k], -yaw[k]], length[k])
    assert np.all(np.isfinite(tip)) and np.all(tension >= 0.0)
