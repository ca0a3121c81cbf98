"""The trapezoidal velocity profile, sampled at the SYNC period.

Distance d at peak velocity v and acceleration a: accelerate for t_a = v/a, cruise, brake.
When d < v^2/a the cruise vanishes and the peak is v' = sqrt(a d) (a triangle):

    s(t) = a t^2 / 2                          0 <= t < t_a
         = a t_a^2 / 2 + v' (t - t_a)         t_a <= t < t_a + t_c,   t_c = (d - a t_a^2) / v'
         = d - a (T_end - t)^2 / 2            up to T_end = 2 t_a + t_c

Sampled exactly at t = T, 2T, ... (the last sample is d), so first differences / T never
exceed v and second differences / T^2 never exceed a (they average s'' over 2T).
"""
from __future__ import annotations

import math

import numpy as np


def trapezoid_samples(distance: float, velocity: float, acceleration: float, period_s: float) -> np.ndarray:
    """Positions s(kT), k = 1..K, from 0 to `distance` (>= 0); empty when distance is 0."""
    if distance <= 0.0:
        return np.empty(0)
    t_accel = velocity / acceleration
    if distance < velocity * t_accel:
        t_accel = math.sqrt(distance / acceleration)
    peak = acceleration * t_accel
    t_cruise = (distance - acceleration * t_accel ** 2) / peak
    t_end = 2.0 * t_accel + t_cruise
    t = period_s * np.arange(1, int(math.ceil(t_end / period_s - 1e-9)) + 1)
    s = np.where(t < t_accel, 0.5 * acceleration * t ** 2,
                 np.where(t < t_accel + t_cruise, 0.5 * acceleration * t_accel ** 2 + peak * (t - t_accel),
                          distance - 0.5 * acceleration * np.maximum(t_end - t, 0.0) ** 2))
    s[-1] = distance
    return s
