"""Keep operator motion inside the tendon tension limits: slow down, then refuse the raising direction.

With a tendon's load ratio rho_k = T_k / T_max,k (T_k the larger of the measured drive tension
and the model's forecast at the target), the jog speed is scaled by

    s = 1                                          for max_k rho_k <= slow_ratio
    s = (refuse_ratio - rho) / (refuse_ratio - slow_ratio), at least min_speed_scale, in between

and a target change that raises a loaded tendon's tension is refused once rho_k >= refuse_ratio.
A change raises tendon k's tension when it pulls tendon k (du_k > 0) or shortens the free length
while the catheter is bent (the tension a bend needs grows as 1/L, control.path_tension). Paying
out, or extending, is always allowed: that is how the operator backs off. The drives' safety stop
at T_max stays the last line of defence.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

PULL_EPSILON_MM = 0.005   # smaller changes (a few encoder counts) are not motion


@dataclass(frozen=True)
class GovernorVerdict:
    """speed_scale: factor on the jog speed, in (0, 1]; refused_tendon: index of the tendon whose
    raise was refused (None when the change is allowed); load_n: the tension estimate it used."""

    speed_scale: float
    refused_tendon: int | None
    load_n: np.ndarray


@dataclass(frozen=True)
class TensionGovernor:
    max_tension_n: tuple[float, float, float, float]
    slow_ratio: float = 0.7
    refuse_ratio: float = 0.9
    min_speed_scale: float = 0.1

    def __post_init__(self) -> None:
        if not 0.0 < self.slow_ratio < self.refuse_ratio < 1.0:
            raise ValueError(f"tension governor needs 0 < slow_ratio < refuse_ratio < 1, got "
                             f"{self.slow_ratio}, {self.refuse_ratio}")
        if len(self.max_tension_n) != 4 or not all(t > 0 for t in self.max_tension_n):
            raise ValueError(f"tension governor needs four positive max_tension_n, got {self.max_tension_n!r}")

    def speed_scale(self, load_n: Sequence[float]) -> float:
        """The speed factor s for the tension estimate load_n (4,) [N] (module docstring)."""
        ratio = float(np.max(np.asarray(load_n, dtype=float) / np.asarray(self.max_tension_n)))
        if ratio <= self.slow_ratio:
            return 1.0
        scale = (self.refuse_ratio - ratio) / (self.refuse_ratio - self.slow_ratio)
        return float(min(1.0, max(self.min_speed_scale, scale)))

    def judge(self, load_n: Sequence[float], from_tendon_mm: Sequence[float], to_tendon_mm: Sequence[float],
              from_insertion_mm: float, to_insertion_mm: float) -> GovernorVerdict:
        """Allow or refuse the change of target from (from_tendon_mm, from_insertion_mm) to
        (to_tendon_mm, to_insertion_mm) given the tension estimate load_n (4,) [N] at the target."""
        load = np.asarray(load_n, dtype=float)
        pulled = np.asarray(to_tendon_mm, dtype=float) - np.asarray(from_tendon_mm, dtype=float) > PULL_EPSILON_MM
        shortened = to_insertion_mm < from_insertion_mm - PULL_EPSILON_MM
        ratio = load / np.asarray(self.max_tension_n)
        raising = (ratio >= self.refuse_ratio) & (pulled | shortened)
        refused = int(np.argmax(np.where(raising, ratio, -1.0))) if raising.any() else None
        return GovernorVerdict(self.speed_scale(load), refused, load)
