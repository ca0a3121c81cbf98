"""Profile-position moves of several axes that start and end together on a straight line.

Every axis runs a trapezoid with the same timing: accelerate for t_a, cruise, decelerate for
t_a, total T. Axis i with distance d_i then needs

    v_i = d_i / (T - t_a),    a_i = v_i / t_a,

so x_i(t) = x_i(0) + d_i f(t) with one shape f for all axes: the move is a straight line in
axis space, and a tendon pair whose sum u1 + u3 is the same at start and end keeps that sum
(the pretension) all the way. With c = T - t_a, the limits v_i <= v_max,i and a_i <= a_max,i read

    c >= D_v = max_i d_i / v_max,i,    t_a c >= D_a = max_i d_i / a_max,i,    t_a <= c,

and the shortest move is c = max(D_v, sqrt(D_a)), t_a = D_a / c, T = t_a + c.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

#: Distances below this are no move (far below one encoder count; avoids dividing by ~0).
NEGLIGIBLE_MM = 1e-9


@dataclass(frozen=True)
class AxisProfile:
    """Profile velocity (mm/s) and acceleration = deceleration (mm/s^2) of one axis."""

    velocity_mm_s: float
    acceleration_mm_s2: float


@dataclass(frozen=True)
class SynchronizedMove:
    duration_s: float
    acceleration_time_s: float
    profiles: tuple[AxisProfile, ...]


def synchronized_move(distances_mm: Sequence[float], max_velocity_mm_s: Sequence[float],
                      max_acceleration_mm_s2: Sequence[float]) -> SynchronizedMove:
    """The shortest common-timing move (module docstring); a zero distance gets a zero profile."""
    lengths = [abs(distance) if abs(distance) > NEGLIGIBLE_MM else 0.0 for distance in distances_mm]
    d_v = max((d / v for d, v in zip(lengths, max_velocity_mm_s)), default=0.0)
    d_a = max((d / a for d, a in zip(lengths, max_acceleration_mm_s2)), default=0.0)
    if d_v == 0.0 and d_a == 0.0:
        return SynchronizedMove(0.0, 0.0, tuple(AxisProfile(0.0, 0.0) for _ in lengths))
    cruise_s = max(d_v, math.sqrt(d_a))
    acceleration_time_s = d_a / cruise_s
    profiles = tuple(AxisProfile(d / cruise_s, d / cruise_s / acceleration_time_s) for d in lengths)
    return SynchronizedMove(acceleration_time_s + cruise_s, acceleration_time_s, profiles)
