"""The commanded input paths of the studies: articulation ramps, plane sweeps, insertion cycles.

All paths are sampled; the model sub-steps between samples (DahlCatheter.max_tendon_step_mm),
so the sample spacing sets the resolution of the recorded tip path, not the physics.
Tendon inputs come from the constant-curvature inverse (paper Fig. 2.4),
u_k = r theta cos(phi_k - phi), so theta is the articulation that constant curvature promises.
"""
from __future__ import annotations

import math

import numpy as np

from model import CatheterParams, tendons_from_articulation


def ramp(start: float, stop: float, step: float) -> np.ndarray:
    """Evenly spaced samples after `start` up to and including `stop`, at most `step` apart."""
    count = max(1, math.ceil(abs(stop - start) / step))
    return np.linspace(start, stop, count + 1)[1:]


def articulation_tendons_mm(params: CatheterParams, theta_deg, plane_deg) -> np.ndarray:
    """Tendon inputs [T, 4] in mm for articulations theta_deg[T] in planes plane_deg[T] (broadcast)."""
    theta_rad, plane_rad = np.broadcast_arrays(np.deg2rad(np.atleast_1d(theta_deg)),
                                               np.deg2rad(np.atleast_1d(plane_deg)))
    return np.array([tendons_from_articulation(t, p, params.tendon_offset_mm)
                     for t, p in zip(theta_rad, plane_rad)])


def articulation_ramp_mm(params: CatheterParams, from_deg: float, to_deg: float, step_deg: float,
                         plane_deg: float = 0.0) -> np.ndarray:
    """Tendon inputs [T, 4] in mm articulating from from_deg to to_deg in one bending plane."""
    return articulation_tendons_mm(params, ramp(from_deg, to_deg, step_deg), plane_deg)


def plane_sweep_mm(params: CatheterParams, theta_deg: float, from_plane_deg: float, to_plane_deg: float,
                   step_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """Constant articulation while the bending plane turns: (plane angles [T] in deg, tendons [T, 4] in mm).

    All four tendons move (paper IV: "guided along the circular path by each of the four
    articulation control tendons"), the catheter is not rolled.
    """
    planes_deg = ramp(from_plane_deg, to_plane_deg, step_deg)
    return planes_deg, articulation_tendons_mm(params, theta_deg, planes_deg)


def insertion_cycle_mm(waypoints_mm: tuple[float, ...], step_mm: float) -> np.ndarray:
    """Free length [T] in mm along straight segments through the waypoints (the first is the start)."""
    return np.concatenate([ramp(a, b, step_mm) for a, b in zip(waypoints_mm, waypoints_mm[1:])])
