"""Keep commands inside the tendon and insertion ranges and the velocity limits, pretension kept.

Commands are limited in the coordinates x = (p_x, p_y, L): the differential pulls of the
pairs 1/3 and 2/4 and the free length [mm]. Tendon k moves by +-dp, so clipping p to
|p| <= min(u_max - u0, u0 - u_min) keeps both tendons of a pair in range with the
pretension u0 unchanged, and |dp| <= v_t T per SYNC period T bounds every tendon's velocity.
"""
from __future__ import annotations

import numpy as np

from control.motion_limits import MotionLimits
from control.workspace import Workspace


class CommandLimiter:
    """Remembers the last command sent; `bounds` is the box the next command may lie in."""

    def __init__(self, workspace: Workspace, limits: MotionLimits, period_s: float):
        self.workspace = workspace
        self.limits = limits
        self.period_s = float(period_s)
        self.reset()

    def reset(self, pulls_mm=(0.0, 0.0), insertion_mm: float | None = None) -> None:
        """Start from this command (default: straight, at the workspace's home free length)."""
        insertion = self.workspace.home_insertion_mm if insertion_mm is None else insertion_mm
        self.previous = np.array([pulls_mm[0], pulls_mm[1], insertion], dtype=float)

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(lower, upper) of x = (p_x, p_y, L) for the next command: ranges intersected with the rate box."""
        pull = self.workspace.max_pull_mm
        step = np.array([self.limits.tendon_velocity_mm_s, self.limits.tendon_velocity_mm_s,
                         self.limits.insertion_velocity_mm_s]) * self.period_s
        lower = np.maximum([-pull, -pull, self.workspace.min_insertion_mm], self.previous - step)
        upper = np.minimum([pull, pull, self.workspace.max_insertion_mm], self.previous + step)
        return lower, np.maximum(upper, lower)

    def limit(self, x) -> tuple[np.ndarray, bool]:
        """x clipped to `bounds`, and whether anything was cut; the result becomes the previous command."""
        x = np.asarray(x, dtype=float)
        lower, upper = self.bounds()
        limited = np.clip(x, lower, upper)
        self.previous = limited
        return limited.copy(), bool(np.any(np.abs(limited - x) > 1e-12))
