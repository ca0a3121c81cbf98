"""Constant-curvature inverse kinematics: a tip position, or pitch/yaw/insertion, to tendon commands.

A single arc of free length L bent by theta toward the direction `plane` (bend vector
b = theta (cos plane, sin plane), model.constant_curvature) puts the tip at

    tip = (L/theta) ((1 - cos theta) cos plane, (1 - cos theta) sin plane, sin theta).

Inverse: plane = atan2(y, x). With rho = hypot(x, y), rho/z = (1 - cos theta)/sin theta
= tan(theta/2), so theta = 2 atan2(rho, z) in [0, 2 pi), and the chord |tip| =
2 (L/theta) sin(theta/2) gives L = |tip| (theta/2) / sin(theta/2) (L = |tip| at theta = 0).

Tendons (antagonistic pairs 1/3 and 2/4, paper Fig. 2.4): the differential pulls
p = r b [mm] and the pretension u0 give u = (u0 + p_x, u0 + p_y, u0 - p_x, u0 - p_y),
i.e. u_k = r theta cos(phi_k - plane) + u0 (model.tendons_from_articulation).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from model import CatheterParams, ConstantCurvature

from control.errors import ControlInputError

THETA_SMALL_RAD = 1e-9


@dataclass(frozen=True)
class Articulation:
    """theta_rad >= 0: total bend angle; plane_rad: direction it bends toward (0 = +x, tendon 1);
    insertion_mm: free length out of the support tube."""

    theta_rad: float
    plane_rad: float
    insertion_mm: float

    @property
    def bend_rad(self) -> np.ndarray:
        """Bend vector theta (cos plane, sin plane) = (pitch, yaw)."""
        return self.theta_rad * np.array([math.cos(self.plane_rad), math.sin(self.plane_rad)])

    @classmethod
    def from_bend(cls, bend_rad, insertion_mm: float) -> "Articulation":
        bx, by = (float(v) for v in bend_rad)
        return cls(math.hypot(bx, by), math.atan2(by, bx), float(insertion_mm))


def articulation_from_pitch_yaw(pitch_rad: float, yaw_rad: float, insertion_mm: float) -> Articulation:
    """Pitch bends toward +x (tendon 1), yaw toward +y (tendon 2): the bend vector (pitch, yaw)."""
    values = {"pitch_rad": pitch_rad, "yaw_rad": yaw_rad, "insertion_mm": insertion_mm}
    _require_finite(values)
    return Articulation.from_bend((pitch_rad, yaw_rad), insertion_mm)


def articulation_from_tip(tip_mm) -> Articulation:
    """The constant-curvature articulation and free length that put the tip at tip_mm (module docstring)."""
    tip = np.asarray(tip_mm, dtype=float).reshape(-1)
    if tip.shape != (3,) or not np.isfinite(tip).all():
        raise ControlInputError(f"target tip must be 3 finite coordinates in mm, got {tip_mm!r}")
    x, y, z = tip
    rho = math.hypot(x, y)
    distance = math.hypot(rho, z)
    theta = 2.0 * math.atan2(rho, z)
    half = 0.5 * theta
    if distance == 0.0 or (rho == 0.0 and z < 0.0):
        raise ControlInputError(f"target tip {tip.tolist()} mm is not reachable by a constant-curvature arc "
                                f"(it lies on the catheter axis at or behind the tube exit); pick a point with "
                                f"z > 0 or off the axis")
    length = distance if theta < THETA_SMALL_RAD else distance * half / math.sin(half)
    return Articulation(theta, math.atan2(y, x) if rho > 0.0 else 0.0, length)


def tip_from_articulation(articulation: Articulation, params: CatheterParams) -> np.ndarray:
    """Constant-curvature tip [mm] of an articulation (model.ConstantCurvature)."""
    tendons = tendons_from_pulls(params.tendon_offset_mm * articulation.bend_rad, 0.0)
    return ConstantCurvature(params).tip_mm(tendons, articulation.insertion_mm)


def tendons_from_pulls(pulls_mm, pretension_mm: float) -> np.ndarray:
    """u = (u0 + p_x, u0 + p_y, u0 - p_x, u0 - p_y) [mm] from the differential pulls p of the pairs."""
    px, py = (float(v) for v in pulls_mm)
    return np.array([pretension_mm + px, pretension_mm + py, pretension_mm - px, pretension_mm - py])


def pulls_from_tendons(tendon_mm) -> np.ndarray:
    """The differential pulls ((u1 - u3)/2, (u2 - u4)/2) [mm]; the common mode is the pretension."""
    u = np.asarray(tendon_mm, dtype=float)
    return np.array([(u[0] - u[2]) / 2.0, (u[1] - u[3]) / 2.0])


def tendons_from_articulation(articulation: Articulation, tendon_offset_mm: float,
                              pretension_mm: float) -> np.ndarray:
    """The constant-curvature inverse to tendon commands: pulls r*b plus the pretension."""
    return tendons_from_pulls(tendon_offset_mm * articulation.bend_rad, pretension_mm)


def _require_finite(values: dict[str, float]) -> None:
    for name, value in values.items():
        if not isinstance(value, (int, float, np.floating, np.integer)) or not math.isfinite(value):
            raise ControlInputError(f"{name} must be a finite number, got {value!r}")
