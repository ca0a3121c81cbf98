"""The seed paper's history scenario (Fig. 4.4): articulate to 180 deg, then move left and right.

With constant curvature the tip would move along a horizontal line; with friction the path
deflects, and differently depending on the friction state built up on the way in.
"Left" adds side_rad to the bend vector perpendicular to the bending plane (toward
+90 deg from it), "right" subtracts it.
"""
from __future__ import annotations

import math

import numpy as np

from control.inverse_kinematics import Articulation
from control.motion_limits import MotionLimits
from control.trajectories.path_builder import PathBuilder, require_finite
from control.trajectories.trajectory import Trajectory
from control.workspace import Workspace


def history_scenario(workspace: Workspace, limits: MotionLimits = MotionLimits(), *,
                     articulation_rad: float = math.pi, plane_rad: float = 0.0, side_rad: float = 0.3,
                     velocity_rad_s: float, acceleration_rad_s2: float, hold_s: float = 0.5,
                     period_s: float = 0.01, start: Articulation | None = None) -> Trajectory:
    """Segments "articulate", "hold", "left", "hold left", "center", "right", "hold right", "center again"."""
    require_finite(articulation_rad=articulation_rad, plane_rad=plane_rad, side_rad=side_rad)
    path = PathBuilder(workspace, limits, period_s, start)
    length = path.insertion_mm
    bent = articulation_rad * np.array([math.cos(plane_rad), math.sin(plane_rad)])
    side = side_rad * np.array([-math.sin(plane_rad), math.cos(plane_rad)])
    rates = {"bend_velocity_rad_s": velocity_rad_s, "bend_acceleration_rad_s2": acceleration_rad_s2}
    path.line(bent, length, "articulate", **rates)
    path.hold(hold_s, "hold")
    path.line(bent + side, length, "left", **rates)
    path.hold(hold_s, "hold left")
    path.line(bent, length, "center", **rates)
    path.line(bent - side, length, "right", **rates)
    path.hold(hold_s, "hold right")
    path.line(bent, length, "center again", **rates)
    return path.build()
