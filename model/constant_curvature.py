"""Constant-curvature baseline (Webster & Jones style), the reference for every comparison.

With four tendons at radius r and angles 0, 90, 180, 270 deg, an inextensible catheter of
free length L bent as one circular arc shortens the lumen of tendon k by r*theta*cos(phi_k - phi).
Antagonistic pairs therefore give the bend vector (paper Fig. 2.4):

    theta * (cos phi, sin phi) = ((u1 - u3)/2, (u2 - u4)/2) / r

Any common-mode pull (pretension) is absorbed and does not bend the catheter.
"""
from __future__ import annotations

import numpy as np

from model.backbone_geometry import arc_transform, compose_backbone
from model.params import CatheterParams

TENDON_ANGLES_RAD = np.deg2rad([0.0, 90.0, 180.0, 270.0])


def bend_from_tendons(tendons_mm: np.ndarray, tendon_offset_mm: float) -> np.ndarray:
    """Total bend vector theta*(cos phi, sin phi) [rad] of a constant-curvature arc."""
    u = np.asarray(tendons_mm, dtype=float)
    return np.array([(u[0] - u[2]) / 2.0, (u[1] - u[3]) / 2.0]) / tendon_offset_mm


def tendons_from_articulation(theta_rad: float, plane_rad: float, tendon_offset_mm: float,
                              pretension_mm: float = 0.0) -> np.ndarray:
    """The constant-curvature inverse: u_k = r*theta*cos(phi_k - plane) + pretension [mm]."""
    return tendon_offset_mm * theta_rad * np.cos(TENDON_ANGLES_RAD - plane_rad) + pretension_mm


def tip_from_tendons_mm(tendons_mm, insertion_mm: float, tendon_offset_mm: float) -> np.ndarray:
    """Tip position [mm] in the base frame of the arc the tendons bend (free length insertion_mm)."""
    bx, by = bend_from_tendons(tendons_mm, tendon_offset_mm)
    rot = np.empty((3, 3))
    tip = np.empty(3)
    arc_transform(bx, by, float(insertion_mm), rot, tip)
    return tip


class ConstantCurvature:
    """Constant-curvature map from tendon displacements and free length to the catheter shape."""

    def __init__(self, params: CatheterParams):
        self.params = params

    def tip_mm(self, tendons_mm, insertion_mm: float) -> np.ndarray:
        """Tip position [mm] in the base frame."""
        return tip_from_tendons_mm(tendons_mm, insertion_mm, self.params.tendon_offset_mm)

    def backbone_mm(self, tendons_mm, insertion_mm: float, n_points: int = 21) -> np.ndarray:
        """(n_points, 3) points evenly spaced along the arc from the tube exit to the tip."""
        n = n_points - 1
        bend = np.tile(bend_from_tendons(tendons_mm, self.params.tendon_offset_mm) / n, (n, 1))
        points = np.empty((n_points, 3))
        frames = np.empty((n_points, 3, 3))
        compose_backbone(bend, np.full(n, float(insertion_mm) / n), points, frames)
        return points
