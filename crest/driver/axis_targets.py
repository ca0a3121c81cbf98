"""Set-points for the five axes, and the antagonistic tendon pairs that produce them.

Tendon k sits at (k-1)*90 deg from +x toward +y; a positive tendon position means pulled.
Tendons 1 and 3 (and 2 and 4) pull against each other. A pair is commanded by one differential
pull d and keeps the configured pretension p on both tendons:

    u1 = p + d13    u3 = p - d13    u2 = p + d24    u4 = p - d24

so u1 + u3 = u2 + u4 = 2 p whatever the bend, and d13 = (u1 - u3) / 2 bends toward +x.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from crest.config.testbed_config import INSERTION_AXIS_NAME, TENDON_AXIS_NAMES

#: The order of axes in every per-axis tuple the driver returns.
AXIS_ORDER = TENDON_AXIS_NAMES + (INSERTION_AXIS_NAME,)


@dataclass(frozen=True)
class AxisTargets:
    """Positions in mm: ``tendon_mm`` for tendon1..tendon4, ``insertion_mm`` the free length."""

    tendon_mm: tuple[float, float, float, float]
    insertion_mm: float

    def __post_init__(self) -> None:
        if len(self.tendon_mm) != len(TENDON_AXIS_NAMES):
            raise ValueError(f"tendon_mm needs {len(TENDON_AXIS_NAMES)} values (tendon1..tendon4), "
                             f"got {len(self.tendon_mm)}")
        object.__setattr__(self, "tendon_mm", tuple(float(value) for value in self.tendon_mm))
        object.__setattr__(self, "insertion_mm", float(self.insertion_mm))
        for name, value in self.by_axis().items():
            if not math.isfinite(value):
                raise ValueError(f"{name}: set-point {value!r} mm is not a finite number")

    @classmethod
    def from_pulls(cls, pull_13_mm: float, pull_24_mm: float, insertion_mm: float,
                   pretension_mm: float) -> AxisTargets:
        """The set-points of two differential pulls around the pretension (module docstring)."""
        return cls(tendon_mm=(pretension_mm + pull_13_mm, pretension_mm + pull_24_mm,
                              pretension_mm - pull_13_mm, pretension_mm - pull_24_mm),
                   insertion_mm=insertion_mm)

    @classmethod
    def from_axis_values(cls, values_mm: tuple[float, ...]) -> AxisTargets:
        """From five values in AXIS_ORDER."""
        return cls(tendon_mm=tuple(values_mm[:4]), insertion_mm=values_mm[4])

    @property
    def pulls_mm(self) -> tuple[float, float]:
        """(d13, d24): the differential pulls, (u1 - u3) / 2 and (u2 - u4) / 2."""
        u1, u2, u3, u4 = self.tendon_mm
        return (u1 - u3) / 2.0, (u2 - u4) / 2.0

    def values(self) -> tuple[float, ...]:
        """The five positions in AXIS_ORDER."""
        return self.tendon_mm + (self.insertion_mm,)

    def by_axis(self) -> dict[str, float]:
        return dict(zip(AXIS_ORDER, self.values()))
