"""Trajectories put the constant-curvature tip where the paper's scenarios say, at the SYNC period."""
import math

import numpy as np
import pytest

from control import Articulation, tip_from_articulation
from control.inverse_kinematics import tendons_from_articulation
from control.trajectories import (articulation_sweep, circle, history_scenario, insertion_at_articulation,
                                  point_to_point)


def test_circle_tip_runs_on_the_constant_curvature_circle(workspace, limits):
    theta, length = math.radians(120), 70.0
    trajectory = circle(workspace, limits, articulation_rad=theta, circle_period_s=6.0, insertion_mm=length,
                        lead_in_velocity_rad_s=1.0, lead_in_acceleration_rad_s2=2.0)
    on_circle = trajectory.tip_mm[trajectory.mask("circle")]
    assert np.allclose(np.hypot(on_circle[:, 0], on_circle[:, 1]), length * (1 - math.cos(theta)) / theta)
    assert np.allclose(on_circle[:, 2], length * math.sin(theta) / theta)
    angles = np.unwrap(np.concatenate([[0.0], np.arctan2(on_circle[:, 1], on_circle[:, 0])]))  # from the lead-in
    assert angles[-1] == pytest.approx(2 * math.pi, abs=1e-9)
    assert np.all(np.diff(angles) > 0)   # all four tendons guide it round, never backwards
    assert np.allclose(trajectory.tip_mm[-1], [0, 0, 80.0])   # back at the start


def test_setpoints_come_at_the_sync_period_and_carry_their_articulation(workspace, limits, params):
    trajectory = articulation_sweep(workspace, limits, angle_rad=math.radians(90), plane_rad=0.5,
                                    velocity_rad_s=1.0, acceleration_rad_s2=2.0, hold_s=0.2)
    setpoints = list(trajectory)
    assert np.allclose(np.diff([sp.t_s for sp in setpoints]), 0.01)
    peak = max(setpoints, key=lambda sp: sp.theta_rad)
    assert peak.theta_rad == pytest.approx(math.radians(90)) and peak.plane_rad == pytest.approx(0.5)
    assert [lab for lab in dict.fromkeys(trajectory.labels)] == ["out", "hold", "back"]
    assert trajectory.mask("hold").sum() == 20


def test_point_to_point_reaches_each_waypoint_in_trapezoid_time(workspace, limits):
    r = workspace.tendon_offset_mm
    target = Articulation(math.radians(60), 0.0, 80.0)
    trajectory = point_to_point(workspace, limits, waypoints=[target], tendon_velocity_mm_s=5.0,
                                tendon_acceleration_mm_s2=50.0, hold_s=0.1)
    move = trajectory.mask("move 1")
    distance = r * target.theta_rad   # tendon 1 travel
    expected_s = distance / 5.0 + 5.0 / 50.0   # d/v + v/a for a trapezoid that reaches v
    assert move.sum() * 0.01 == pytest.approx(expected_s, abs=0.011)
    assert np.allclose(trajectory.bend_rad[move][-1], target.bend_rad)
    assert np.allclose(trajectory.bend_rad[trajectory.mask("hold 1")], target.bend_rad)


def test_insertion_keeps_the_articulation_constant(workspace, limits):
    trajectory = insertion_at_articulation(workspace, limits, articulation_rad=math.pi, insertion_to_mm=95.0,
                                           insertion_velocity_mm_s=5.0, insertion_acceleration_mm_s2=20.0,
                                           articulation_velocity_rad_s=1.0, articulation_acceleration_rad_s2=2.0)
    insert = trajectory.mask("insert")
    assert np.allclose(trajectory.theta_rad[insert], math.pi)
    assert trajectory.insertion_mm[insert][-1] == pytest.approx(95.0)
    # at 180 deg the constant-curvature tip stays level with the tube exit: a horizontal line (paper Fig. 4.2)
    assert np.allclose(trajectory.tip_mm[insert][:, 2], 0.0, atol=1e-9)


def test_history_scenario_moves_left_and_right_of_the_bending_plane(workspace, limits, params):
    trajectory = history_scenario(workspace, limits, side_rad=0.3, velocity_rad_s=1.0, acceleration_rad_s2=2.0,
                                  hold_s=0.2)
    left = trajectory.tip_mm[trajectory.mask("hold left")][-1]
    right = trajectory.tip_mm[trajectory.mask("hold right")][-1]
    assert np.allclose(left, tip_from_articulation(Articulation.from_bend((math.pi, 0.3), 80.0), params))
    assert left[1] > 4.0 and right[1] < -4.0
    assert np.allclose(left * [1, -1, 1], right)
    assert trajectory.theta_rad[trajectory.mask("hold")][0] == pytest.approx(math.pi)


def test_tendon_commands_of_a_trajectory_start_from_rest(workspace, limits):
    trajectory = circle(workspace, limits, articulation_rad=math.radians(90), circle_period_s=5.0,
                        lead_in_velocity_rad_s=1.0, lead_in_acceleration_rad_s2=2.0)
    first = tendons_from_articulation(Articulation.from_bend(trajectory.bend_rad[0], 80.0),
                                      workspace.tendon_offset_mm, workspace.pretension_mm)
    # one period of constant acceleration from rest: a*T^2/2 of bend, times r
    assert np.abs(first - workspace.pretension_mm).max() == pytest.approx(2.5 * 2.0 * 0.01 ** 2 / 2, rel=1e-6)


def test_trajectories_chain_where_the_last_one_ended(workspace, limits):
    out = articulation_sweep(workspace, limits, angle_rad=math.radians(90), velocity_rad_s=1.0,
                             acceleration_rad_s2=2.0, back=False)
    onward = point_to_point(workspace, limits, waypoints=[Articulation(math.radians(90), 0.0, 60.0)],
                            tendon_velocity_mm_s=5.0, tendon_acceleration_mm_s2=50.0, start=out.end)
    assert np.allclose(onward.bend_rad, out.bend_rad[-1])   # only the free length moves
    assert onward.insertion_mm[-1] == pytest.approx(60.0)
    assert onward.duration_s == pytest.approx(len(onward) * 0.01)
