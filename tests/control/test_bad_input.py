"""Issue 5, claim 4: a target outside the workspace, a NaN or a too-fast trajectory is refused
before any axis moves, with a message that says what to change.

Trajectories are checked whole when they are built, so a bad last sample refuses the entire
trajectory before its first set-point exists; controllers refuse a bad set-point without
changing their state.
"""
import dataclasses
import math

import numpy as np
import pytest

from control import (Articulation, ControlInputError, SetPoint, TrajectoryError, make_controller,
                     tip_from_articulation)
from control.trajectories import articulation_sweep, circle, history_scenario, point_to_point


def test_articulation_beyond_the_workspace_is_refused(workspace, limits):
    with pytest.raises(TrajectoryError, match=r"300\.0 deg exceeds the workspace maximum 270\.0 deg"):
        articulation_sweep(workspace, limits, angle_rad=math.radians(300), velocity_rad_s=1.0,
                           acceleration_rad_s2=2.0)


def test_tip_target_beyond_the_free_length_range_is_refused(workspace, limits):
    with pytest.raises(TrajectoryError, match=r"waypoint 1 .*free length 150\.00 mm is outside"):
        point_to_point(workspace, limits, waypoints=[(0.0, 0.0, 150.0)], tendon_velocity_mm_s=5.0,
                       tendon_acceleration_mm_s2=50.0)


def test_bad_last_waypoint_refuses_the_whole_trajectory(workspace, limits):
    good = Articulation(math.radians(45), 0.0, 80.0)
    with pytest.raises(TrajectoryError, match="waypoint 3"):
        point_to_point(workspace, limits, waypoints=[good, good, (0.0, 0.0, -20.0)], tendon_velocity_mm_s=5.0,
                       tendon_acceleration_mm_s2=50.0)


@pytest.mark.parametrize("build,match", [
    (lambda ws, lim: articulation_sweep(ws, lim, angle_rad=math.nan, velocity_rad_s=1.0, acceleration_rad_s2=2.0),
     "angle_rad must be a finite number"),
    (lambda ws, lim: circle(ws, lim, articulation_rad=math.pi, circle_period_s=math.nan, lead_in_velocity_rad_s=1.0,
                            lead_in_acceleration_rad_s2=2.0), "circle_period_s must be a finite number > 0"),
    (lambda ws, lim: point_to_point(ws, lim, waypoints=[(10.0, math.nan, 60.0)], tendon_velocity_mm_s=5.0,
                                    tendon_acceleration_mm_s2=50.0), "waypoint 1: target tip must be 3 finite"),
    (lambda ws, lim: history_scenario(ws, lim, velocity_rad_s=1.0, acceleration_rad_s2=math.inf),
     "bend_acceleration_rad_s2 must be a finite number > 0"),
])
def test_nan_is_refused_naming_the_argument(workspace, limits, build, match):
    with pytest.raises(TrajectoryError, match=match):
        build(workspace, limits)


def test_too_fast_sweep_is_refused_naming_the_tendon(workspace, limits):
    # omega = 10 rad/s moves tendon 1 at r*omega = 25 mm/s > 20 mm/s
    expected = r"tendon 1 velocity 25\.0 mm/s exceeds the configured maximum 20\.0 mm/s \(first at t="
    with pytest.raises(TrajectoryError, match=expected):
        articulation_sweep(workspace, limits, angle_rad=math.radians(120), velocity_rad_s=10.0,
                           acceleration_rad_s2=50.0)


def test_too_fast_circle_is_refused(workspace, limits):
    # r*theta*omega = 2.5*pi*2*pi/2 = 24.7 mm/s > 20 mm/s
    with pytest.raises(TrajectoryError, match=r"tendon \d velocity .*exceeds"):
        circle(workspace, limits, articulation_rad=math.pi, circle_period_s=2.0, lead_in_velocity_rad_s=1.0,
               lead_in_acceleration_rad_s2=2.0)


def test_too_hard_acceleration_is_refused(workspace, limits):
    with pytest.raises(TrajectoryError, match=r"tendon 1 acceleration .*exceeds the configured maximum 200\.0"):
        articulation_sweep(workspace, limits, angle_rad=math.radians(90), velocity_rad_s=4.0,
                           acceleration_rad_s2=200.0)


def test_too_fast_insertion_is_refused(workspace, limits):
    with pytest.raises(TrajectoryError, match=r"insertion velocity 20\.0 mm/s exceeds the configured maximum 10\.0"):
        point_to_point(workspace, limits, waypoints=[Articulation(0.0, 0.0, 50.0)], tendon_velocity_mm_s=5.0,
                       tendon_acceleration_mm_s2=50.0, insertion_velocity_mm_s=20.0, insertion_acceleration_mm_s2=50.0)


def test_trajectory_at_exactly_the_limits_is_accepted(workspace, limits):
    r = workspace.tendon_offset_mm
    trajectory = articulation_sweep(workspace, limits, angle_rad=math.radians(180),
                                    velocity_rad_s=limits.tendon_velocity_mm_s / r,
                                    acceleration_rad_s2=limits.tendon_acceleration_mm_s2 / r)
    tendon_1 = np.concatenate([[workspace.pretension_mm], [workspace.pretension_mm],
                               r * trajectory.bend_rad[:, 0] + workspace.pretension_mm])
    assert np.abs(np.diff(tendon_1)).max() / 0.01 == pytest.approx(limits.tendon_velocity_mm_s, rel=1e-6)


@pytest.mark.parametrize("name", ["cc", "dahl", "dahl+fb"])
def test_controllers_refuse_a_bad_setpoint_and_keep_their_state(params, workspace, limits, name):
    controller = make_controller(name, workspace, limits, n_elements=10)
    articulation = Articulation(math.radians(30), 0.0, 80.0)
    good = SetPoint(0.01, tip_from_articulation(articulation, params), articulation.theta_rad, 0.0, 80.0)
    controller.command(good)
    bad_tip = dataclasses.replace(good, t_s=0.02, tip_mm=np.array([1.0, np.nan, 70.0]))
    outside = dataclasses.replace(good, t_s=0.02, theta_rad=math.radians(290))
    for setpoint, match in ((bad_tip, "target tip must be 3 finite"), (outside, "exceeds the workspace maximum")):
        with pytest.raises(ControlInputError, match=match):
            controller.command(setpoint)
    again = controller.command(dataclasses.replace(good, t_s=0.02))
    fresh = make_controller(name, workspace, limits, n_elements=10)
    fresh.command(good)
    expected = fresh.command(dataclasses.replace(good, t_s=0.02))
    assert np.array_equal(again.tendon_mm, expected.tendon_mm)
    assert again.insertion_mm == expected.insertion_mm
