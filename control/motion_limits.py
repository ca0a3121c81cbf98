"""How fast the axes may be commanded (per axis kind, from the testbed configuration)."""
from __future__ import annotations

import math
from dataclasses import dataclass, fields

from control.errors import ControlInputError


@dataclass(frozen=True)
class MotionLimits:
    """Velocity and acceleration limits of the tendon and insertion axes.

    The defaults are configs/testbed.toml [axis_defaults.tendon] and [axis_defaults.insertion]
    (max_velocity_mm_s, max_acceleration_mm_s2).
    """

    tendon_velocity_mm_s: float = 20.0
    tendon_acceleration_mm_s2: float = 200.0
    insertion_velocity_mm_s: float = 10.0
    insertion_acceleration_mm_s2: float = 100.0

    def __post_init__(self) -> None:
        for field in fields(self):
            value = getattr(self, field.name)
            if not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
                raise ControlInputError(f"motion limit {field.name} must be a finite number > 0, got {value!r}")
