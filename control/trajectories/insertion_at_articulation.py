"""Insertion at constant articulation: bend, then change the free length and back (paper Fig. 4.2)."""
from __future__ import annotations

import math

import numpy as np

from control.inverse_kinematics import Articulation
from control.motion_limits import MotionLimits
from control.trajectories.path_builder import PathBuilder, require_finite
from control.trajectories.trajectory import Trajectory
from control.workspace import Workspace


def insertion_at_articulation(workspace: Workspace, limits: MotionLimits = MotionLimits(), *,
                              articulation_rad: float, plane_rad: float = 0.0, insertion_to_mm: float,
                              insertion_velocity_mm_s: float, insertion_acceleration_mm_s2: float,
                              articulation_velocity_rad_s: float, articulation_acceleration_rad_s2: float,
                              back: bool = True, period_s: float = 0.01,
                              start: Articulation | None = None) -> Trajectory:
    """Articulate to articulation_rad in plane_rad at the start's free length ("articulate"),
    move the free length to insertion_to_mm ("insert"), and with `back` return to the start's
    free length ("retract") and straighten ("return"). With constant curvature the tip moves
    on the arc's chord direction; with friction it deflects (the seed paper's Fig. 4.2).
    """
    require_finite(articulation_rad=articulation_rad, plane_rad=plane_rad, insertion_to_mm=insertion_to_mm)
    path = PathBuilder(workspace, limits, period_s, start)
    home_bend, home_length = path.bend_rad, path.insertion_mm
    bent = articulation_rad * np.array([math.cos(plane_rad), math.sin(plane_rad)])
    bend_rates = {"bend_velocity_rad_s": articulation_velocity_rad_s,
                  "bend_acceleration_rad_s2": articulation_acceleration_rad_s2}
    length_rates = {**bend_rates, "insertion_velocity_mm_s": insertion_velocity_mm_s,
                    "insertion_acceleration_mm_s2": insertion_acceleration_mm_s2}
    path.line(bent, home_length, "articulate", **bend_rates)
    path.line(bent, insertion_to_mm, "insert", **length_rates)
    if back:
        path.line(bent, home_length, "retract", **length_rates)
        path.line(home_bend, home_length, "return", **bend_rates)
    return path.build()
