"""Circle in a plane normal to the insertion axis, at a given articulation (paper Fig. 4.3).

The tip is guided by all four tendons, not by rolling the catheter: the bend vector is
b(t) = theta (cos psi(t), sin psi(t)) with constant theta and L, so the constant-curvature tip
runs on the circle of radius L (1 - cos theta)/theta at height z = L sin theta/theta, and
tendon k follows u_k = r theta cos(psi - phi_k) + u0. psi runs on a trapezoid up to
omega = 2 pi / circle_period_s, so |du_k/dt| <= r theta omega and
|d2u_k/dt2| <= r theta (|psi''| + omega^2).
"""
from __future__ import annotations

import math

import numpy as np

from control.inverse_kinematics import Articulation
from control.motion_limits import MotionLimits
from control.trajectories.path_builder import PathBuilder, require_finite, require_positive
from control.trajectories.trajectory import Trajectory
from control.trajectories.trapezoid import trapezoid_samples
from control.workspace import Workspace


def circle(workspace: Workspace, limits: MotionLimits = MotionLimits(), *, articulation_rad: float,
           circle_period_s: float, turns: float = 1.0, start_plane_rad: float = 0.0,
           insertion_mm: float | None = None, lead_in_velocity_rad_s: float, lead_in_acceleration_rad_s2: float,
           angular_acceleration_rad_s2: float | None = None, back: bool = True, period_s: float = 0.01,
           start: Articulation | None = None) -> Trajectory:
    """Segments: "lead-in" (from the start to articulation_rad in start_plane_rad at insertion_mm,
    default the start's free length), "circle" (psi from start_plane_rad through turns*2 pi,
    ramping up and down at angular_acceleration_rad_s2, default omega^2/pi: a quarter turn),
    and with `back` "return" to the start.
    """
    require_finite(articulation_rad=articulation_rad, start_plane_rad=start_plane_rad)
    require_positive(circle_period_s=circle_period_s, turns=turns)
    path = PathBuilder(workspace, limits, period_s, start)
    home_bend, home_length = path.bend_rad, path.insertion_mm
    length = home_length if insertion_mm is None else insertion_mm
    rates = {"bend_velocity_rad_s": lead_in_velocity_rad_s, "bend_acceleration_rad_s2": lead_in_acceleration_rad_s2}
    path.line(articulation_rad * np.array([math.cos(start_plane_rad), math.sin(start_plane_rad)]), length,
              "lead-in", **rates)
    omega = 2.0 * math.pi / circle_period_s
    alpha = omega ** 2 / math.pi if angular_acceleration_rad_s2 is None else angular_acceleration_rad_s2
    require_positive(angular_acceleration_rad_s2=alpha)
    psi = start_plane_rad + trapezoid_samples(2.0 * math.pi * turns, omega, alpha, path.period_s)
    path.samples(articulation_rad * np.column_stack([np.cos(psi), np.sin(psi)]), np.full(len(psi), path.insertion_mm),
                 "circle")
    if back:
        path.line(home_bend, home_length, "return", **rates)
    return path.build()
