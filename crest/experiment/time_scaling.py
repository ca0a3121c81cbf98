"""Slow a sampled set-point path uniformly until every axis is inside its limits.

With a time dilation s >= 1, velocities scale by 1/s and accelerations by 1/s^2, so the
smallest s that fits is s = max(1, max_k |v_k|/(m v_max,k), sqrt(max_k |a_k|/(m a_max,k))) for a
safety margin m < 1. A kink in the sampled path only shrinks by 1/s after resampling, so the
dilation is repeated on the resampled path until it fits. The path's shape, and the ratios
between its speeds, stay the same.
"""
from __future__ import annotations

import math

import numpy as np

from crest.config import TestbedConfig

MARGIN = 0.9


def slow_to_limits(period_s: float, tendon_mm: np.ndarray, insertion_mm: np.ndarray,
                   config: TestbedConfig, max_rounds: int = 8) -> tuple[np.ndarray, np.ndarray, float]:
    """(tendon_mm, insertion_mm) resampled at period_s after dilation, and the total dilation."""
    axes = np.column_stack([tendon_mm, insertion_mm])
    total = 1.0
    for _ in range(max_rounds):
        dilation = _dilation(period_s, axes, config)
        if dilation <= 1.0:
            break
        total *= dilation
        t = np.arange(len(axes)) * period_s
        t_new = np.arange(0.0, t[-1] * dilation + 0.5 * period_s, period_s) / dilation
        axes = np.column_stack([np.interp(t_new, t, axes[:, k]) for k in range(axes.shape[1])])
    return axes[:, :4], axes[:, 4], total


def _dilation(period_s: float, axes: np.ndarray, config: TestbedConfig) -> float:
    limits = config.tendon_axes + (config.insertion_axis,)
    velocity = np.abs(np.diff(axes, axis=0)).max(axis=0) / period_s
    acceleration = np.abs(np.diff(axes, n=2, axis=0)).max(axis=0) / period_s ** 2
    dilation = 1.0
    for k, axis in enumerate(limits):
        dilation = max(dilation, velocity[k] / (MARGIN * axis.max_velocity_mm_s),
                       math.sqrt(acceleration[k] / (MARGIN * axis.max_acceleration_mm_s2)))
    return dilation
