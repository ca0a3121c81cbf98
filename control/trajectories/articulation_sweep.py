"""Articulation sweep: bend to an angle in one plane, hold, and come back (paper Fig. 4.1)."""
from __future__ import annotations

import math

import numpy as np

from control.inverse_kinematics import Articulation
from control.motion_limits import MotionLimits
from control.trajectories.path_builder import PathBuilder, require_finite
from control.trajectories.trajectory import Trajectory
from control.workspace import Workspace


def articulation_sweep(workspace: Workspace, limits: MotionLimits = MotionLimits(), *, angle_rad: float,
                       plane_rad: float = 0.0, velocity_rad_s: float, acceleration_rad_s2: float,
                       hold_s: float = 0.0, back: bool = True, period_s: float = 0.01,
                       start: Articulation | None = None) -> Trajectory:
    """From `start` (default: straight at home) to the bend angle_rad*(cos plane, sin plane) at the
    start's free length, hold for hold_s, then back to the start when `back`.

    Segments "out", "hold", "back". The bend vector moves on a trapezoid at velocity_rad_s
    and acceleration_rad_s2, so tendon k moves at r*omega*|cos(phi_k - plane)| <= r*omega.
    """
    require_finite(angle_rad=angle_rad, plane_rad=plane_rad)
    path = PathBuilder(workspace, limits, period_s, start)
    home_bend, home_length = path.bend_rad, path.insertion_mm
    target = angle_rad * np.array([math.cos(plane_rad), math.sin(plane_rad)])
    rates = {"bend_velocity_rad_s": velocity_rad_s, "bend_acceleration_rad_s2": acceleration_rad_s2}
    path.line(target, home_length, "out", **rates)
    path.hold(hold_s, "hold")
    if back:
        path.line(home_bend, home_length, "back", **rates)
    return path.build()
