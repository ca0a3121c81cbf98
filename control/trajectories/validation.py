"""Refuse a sampled trajectory before anything runs: NaN, outside the workspace, or too fast.

The trajectory is checked as the constant-curvature commands it implies: tendons
u_k = r theta cos(phi_k - plane) + u0 and the free length L, preceded by the start held at
rest. With period T, velocity (x_k - x_k-1)/T and acceleration (x_k - 2 x_k-1 + x_k-2)/T^2
of every tendon and of L must stay within the configured limits (a relative slack of 1e-6
absorbs rounding). The message names the axis, the peak value, where it first
exceeds the limit (time and segment) and what to change.
"""
from __future__ import annotations

import numpy as np

from control.errors import TrajectoryError
from control.inverse_kinematics import Articulation, tendons_from_articulation
from control.motion_limits import MotionLimits
from control.workspace import Workspace

RELATIVE_SLACK = 1e-6


def check_samples(t_s: np.ndarray, bend_rad: np.ndarray, insertion_mm: np.ndarray, labels: list[str],
                  start: Articulation, workspace: Workspace, limits: MotionLimits, period_s: float) -> None:
    """Raise TrajectoryError for the first problem found; return None when the trajectory is acceptable."""
    if len(t_s) == 0:
        raise TrajectoryError("the trajectory is empty: give it a non-zero distance or duration")

    problem = workspace.violation(start)
    if problem is not None:
        raise TrajectoryError(f"the start {start} is outside the workspace: {problem}")

    def where(k: int) -> str:
        return f"at t={t_s[k]:.3f} s ({labels[k]})"

    bad = ~(np.isfinite(bend_rad).all(axis=1) & np.isfinite(insertion_mm))
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise TrajectoryError(f"set-point {where(k)} is not finite (bend {bend_rad[k].tolist()} rad, free length "
                              f"{insertion_mm[k]} mm): check the trajectory's arguments for NaN")
    for k in range(len(t_s)):
        problem = workspace.violation(Articulation.from_bend(bend_rad[k], insertion_mm[k]))
        if problem is not None:
            raise TrajectoryError(f"set-point {where(k)} is outside the workspace: {problem}")

    r = workspace.tendon_offset_mm
    start_bend = start.bend_rad
    bend = np.vstack([start_bend, start_bend, bend_rad])
    length = np.concatenate([[start.insertion_mm] * 2, insertion_mm])
    tendons = np.stack([tendons_from_articulation(Articulation.from_bend(b, 0.0), r, workspace.pretension_mm)
                        for b in bend])
    axes = [(f"tendon {k + 1}", tendons[:, k], limits.tendon_velocity_mm_s, limits.tendon_acceleration_mm_s2)
            for k in range(4)] + [("insertion", length, limits.insertion_velocity_mm_s,
                                   limits.insertion_acceleration_mm_s2)]
    for name, x, v_max, a_max in axes:
        velocity = np.abs(np.diff(x)[1:]) / period_s
        acceleration = np.abs(np.diff(x, 2)) / period_s ** 2
        for value, limit, what, unit in ((velocity, v_max, "velocity", "mm/s"), (acceleration, a_max,
                                                                                 "acceleration", "mm/s^2")):
            over = np.flatnonzero(value > limit * (1.0 + RELATIVE_SLACK))
            if over.size:
                raise TrajectoryError(f"{name} {what} {value.max():.1f} {unit} exceeds the configured maximum "
                                      f"{limit} {unit} (first {where(int(over[0]))}): slow the trajectory down "
                                      f"(lower its velocity or acceleration, or lengthen its period)")
