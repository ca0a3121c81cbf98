"""One set-point of a trajectory: what the tip should do at one SYNC instant."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from control.inverse_kinematics import Articulation


@dataclass(frozen=True)
class SetPoint:
    """t_s: time since the start of the trajectory [s].
    tip_mm: target tip (3,) in the base frame (the constant-curvature tip of the articulation).
    theta_rad, plane_rad, insertion_mm: the constant-curvature articulation and the free length.
    label: the trajectory segment this sample belongs to (e.g. "circle", "hold 2").
    """

    t_s: float
    tip_mm: np.ndarray
    theta_rad: float
    plane_rad: float
    insertion_mm: float
    label: str = ""

    @property
    def articulation(self) -> Articulation:
        return Articulation(self.theta_rad, self.plane_rad, self.insertion_mm)
