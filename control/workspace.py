"""The workspace commands may ask for: the reachable set of the constant-curvature model.

A set-point is inside when its articulation theta <= max_articulation_rad, its free length
lies in [min_insertion_mm, max_insertion_mm], and its constant-curvature tendon commands
u_k = r theta cos(phi_k - plane) + pretension lie in tendon_range_mm.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from model import CatheterParams

from control.errors import ControlInputError
from control.inverse_kinematics import Articulation, tendons_from_articulation

DEFAULT_MAX_ARTICULATION_RAD = 1.5 * math.pi   # 270 deg, the largest articulation in the seed paper (Fig. 4.1)


@dataclass(frozen=True)
class Workspace:
    """params: the controller's catheter model (geometry and ranges come from it).
    max_articulation_rad: largest total bend a target may ask for.
    min_insertion_mm, max_insertion_mm: free-length range (params' range, narrowed by axis soft limits).
    tendon_range_mm: allowed tendon commands (params' range, narrowed by axis soft limits).
    pretension_mm: common-mode pull added to both tendons of each pair.
    home_insertion_mm: free length at rest (where trajectories start by default).
    """

    params: CatheterParams
    max_articulation_rad: float
    min_insertion_mm: float
    max_insertion_mm: float
    tendon_range_mm: tuple[float, float]
    pretension_mm: float
    home_insertion_mm: float

    @classmethod
    def from_params(cls, params: CatheterParams, *, max_articulation_rad: float = DEFAULT_MAX_ARTICULATION_RAD,
                    pretension_mm: float = 0.0, tendon_range_mm: tuple[float, float] | None = None,
                    insertion_range_mm: tuple[float, float] | None = None) -> "Workspace":
        """The workspace of a catheter; tendon/insertion ranges given here only narrow the params' ranges."""
        low, high = params.tendon_range_mm
        if tendon_range_mm is not None:
            low, high = max(low, tendon_range_mm[0]), min(high, tendon_range_mm[1])
        lo_l, hi_l = params.min_free_length_mm, params.max_free_length_mm
        if insertion_range_mm is not None:
            lo_l, hi_l = max(lo_l, insertion_range_mm[0]), min(hi_l, insertion_range_mm[1])
        home = min(max(params.free_length_mm, lo_l), hi_l)
        return cls(params, float(max_articulation_rad), float(lo_l), float(hi_l), (float(low), float(high)),
                   float(pretension_mm), float(home))

    def __post_init__(self) -> None:
        for name in ("max_articulation_rad", "min_insertion_mm", "max_insertion_mm", "pretension_mm"):
            if not math.isfinite(getattr(self, name)):
                raise ControlInputError(f"workspace {name} must be finite, got {getattr(self, name)!r}")
        if not self.max_articulation_rad > 0:
            raise ControlInputError(f"workspace max_articulation_rad must be > 0, got {self.max_articulation_rad}")
        if not self.min_insertion_mm < self.max_insertion_mm:
            raise ControlInputError(f"workspace insertion range [{self.min_insertion_mm}, {self.max_insertion_mm}] "
                                    f"mm is empty: check the axis soft limits against the catheter's free length range")
        low, high = self.tendon_range_mm
        if not low < self.pretension_mm < high:
            raise ControlInputError(f"pretension {self.pretension_mm} mm must lie inside the tendon range "
                                    f"[{low}, {high}] mm")

    @property
    def tendon_offset_mm(self) -> float:
        return self.params.tendon_offset_mm

    @property
    def max_pull_mm(self) -> float:
        """Largest differential pull p with both u0 + p and u0 - p inside the tendon range."""
        low, high = self.tendon_range_mm
        return min(high - self.pretension_mm, self.pretension_mm - low)

    @property
    def home(self) -> Articulation:
        return Articulation(0.0, 0.0, self.home_insertion_mm)

    def violation(self, articulation: Articulation) -> str | None:
        """Why the articulation is outside the workspace (what to change), or None when it is inside."""
        values = (articulation.theta_rad, articulation.plane_rad, articulation.insertion_mm)
        if not all(math.isfinite(v) for v in values):
            return f"articulation {articulation} is not finite"
        if articulation.theta_rad > self.max_articulation_rad * (1.0 + 1e-12):
            return (f"articulation {math.degrees(articulation.theta_rad):.1f} deg exceeds the workspace maximum "
                    f"{math.degrees(self.max_articulation_rad):.1f} deg: lower the target articulation")
        if not self.min_insertion_mm - 1e-9 <= articulation.insertion_mm <= self.max_insertion_mm + 1e-9:
            return (f"free length {articulation.insertion_mm:.2f} mm is outside the insertion range "
                    f"[{self.min_insertion_mm}, {self.max_insertion_mm}] mm")
        tendons = tendons_from_articulation(articulation, self.tendon_offset_mm, self.pretension_mm)
        low, high = self.tendon_range_mm
        outside = np.flatnonzero((tendons < low - 1e-9) | (tendons > high + 1e-9))
        if outside.size:
            k = int(outside[0])
            return (f"tendon {k + 1} would need {tendons[k]:.2f} mm, outside the tendon range [{low}, {high}] mm: "
                    f"lower the articulation")
        return None

    def check(self, articulation: Articulation, what: str) -> None:
        """Raise ControlInputError naming `what` when the articulation is outside the workspace."""
        problem = self.violation(articulation)
        if problem is not None:
            raise ControlInputError(f"{what}: {problem}")
