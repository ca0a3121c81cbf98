"""Builds a trajectory segment by segment, each starting where the previous one ended."""
from __future__ import annotations

import math

import numpy as np

from control.errors import TrajectoryError
from control.inverse_kinematics import Articulation
from control.motion_limits import MotionLimits
from control.trajectories.trajectory import Trajectory
from control.trajectories.trapezoid import trapezoid_samples
from control.workspace import Workspace


def require_positive(**values: float) -> None:
    """TrajectoryError naming the argument unless every value is a finite number > 0."""
    for name, value in values.items():
        if not isinstance(value, (int, float, np.floating, np.integer)) or not math.isfinite(value) or value <= 0:
            raise TrajectoryError(f"{name} must be a finite number > 0, got {value!r}")


def require_finite(**values: float) -> None:
    for name, value in values.items():
        if not isinstance(value, (int, float, np.floating, np.integer)) or not math.isfinite(value):
            raise TrajectoryError(f"{name} must be a finite number, got {value!r}")


class PathBuilder:
    """Samples of the bend vector [rad] and free length [mm] at the SYNC period, with segment labels.

    line(): straight line in (bend, free length) on one synchronised trapezoid s in [0, 1]:
    the bend vector moves at most `bend_velocity_rad_s` in norm (so no tendon faster than
    r times that) and the free length at most `insertion_velocity_mm_s`.
    """

    def __init__(self, workspace: Workspace, limits: MotionLimits, period_s: float, start: Articulation | None):
        require_positive(period_s=period_s)
        self.workspace = workspace
        self.limits = limits
        self.period_s = float(period_s)
        self.start = workspace.home if start is None else start
        require_finite(start_theta_rad=self.start.theta_rad, start_plane_rad=self.start.plane_rad,
                       start_insertion_mm=self.start.insertion_mm)
        self._bend = [np.empty((0, 2))]
        self._insertion = [np.empty(0)]
        self._labels: list[str] = []
        self.bend_rad = self.start.bend_rad
        self.insertion_mm = float(self.start.insertion_mm)

    def samples(self, bend_rad: np.ndarray, insertion_mm: np.ndarray, label: str) -> None:
        """Append raw samples (K, 2) and (K,)."""
        if len(insertion_mm) == 0:
            return
        self._bend.append(np.asarray(bend_rad, dtype=float).reshape(-1, 2))
        self._insertion.append(np.asarray(insertion_mm, dtype=float).reshape(-1))
        self._labels += [label] * len(insertion_mm)
        self.bend_rad = self._bend[-1][-1].copy()
        self.insertion_mm = float(self._insertion[-1][-1])

    def line(self, to_bend_rad, to_insertion_mm: float, label: str, *, bend_velocity_rad_s: float,
             bend_acceleration_rad_s2: float, insertion_velocity_mm_s: float | None = None,
             insertion_acceleration_mm_s2: float | None = None) -> None:
        to_bend = np.asarray(to_bend_rad, dtype=float)
        require_positive(bend_velocity_rad_s=bend_velocity_rad_s, bend_acceleration_rad_s2=bend_acceleration_rad_s2)
        require_finite(target_bend_x_rad=float(to_bend[0]), target_bend_y_rad=float(to_bend[1]),
                       target_insertion_mm=to_insertion_mm)
        problem = self.workspace.violation(Articulation.from_bend(to_bend, to_insertion_mm))
        if problem is not None:
            raise TrajectoryError(f"the target of segment '{label}' is outside the workspace: {problem}")
        d_bend = to_bend - self.bend_rad
        d_length = float(to_insertion_mm) - self.insertion_mm
        velocity, acceleration = math.inf, math.inf
        bend_distance = float(np.hypot(*d_bend))
        if bend_distance > 0:
            velocity = bend_velocity_rad_s / bend_distance
            acceleration = bend_acceleration_rad_s2 / bend_distance
        if abs(d_length) > 0:
            v_l = self.limits.insertion_velocity_mm_s if insertion_velocity_mm_s is None else insertion_velocity_mm_s
            a_l = (self.limits.insertion_acceleration_mm_s2 if insertion_acceleration_mm_s2 is None
                   else insertion_acceleration_mm_s2)
            require_positive(insertion_velocity_mm_s=v_l, insertion_acceleration_mm_s2=a_l)
            velocity = min(velocity, v_l / abs(d_length))
            acceleration = min(acceleration, a_l / abs(d_length))
        if math.isinf(velocity):
            return
        s = trapezoid_samples(1.0, velocity, acceleration, self.period_s)
        self.samples(self.bend_rad + np.outer(s, d_bend), self.insertion_mm + s * d_length, label)

    def hold(self, duration_s: float, label: str) -> None:
        """Stay where the path is for duration_s (rounded to whole periods)."""
        require_finite(hold_s=duration_s)
        count = int(round(max(duration_s, 0.0) / self.period_s))
        self.samples(np.tile(self.bend_rad, (count, 1)), np.full(count, self.insertion_mm), label)

    def build(self) -> Trajectory:
        return Trajectory(np.vstack(self._bend), np.concatenate(self._insertion), self._labels, self.start,
                          self.workspace, self.limits, self.period_s)
