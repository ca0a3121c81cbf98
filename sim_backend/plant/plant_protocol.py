"""The protocol of a plant behind the virtual drives.

Any class with a no-argument constructor and these two methods can be loaded with
`--plant package.module:ClassName`, so a higher-fidelity simulator (a Cosserat rod, FEM, ...)
can replace the default Dahl catheter:

    reset() -> None
    step(dt_s, tendon_mm, insertion_mm) -> (tip_mm, tendon_tension_n)

tendon_mm: 4 tendon displacements [mm], positive = pulled, tendons at 0/90/180/270 deg.
insertion_mm: free length out of the support tube [mm].
tip_mm: 3 tip coordinates [mm] in the base frame (origin at the tube exit, z out of the tube,
x toward tendon 1). tendon_tension_n: 4 tensions [N] at the drives.
"""
from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class Plant(Protocol):
    def reset(self) -> None: ...

    def step(self, dt_s: float, tendon_mm: np.ndarray, insertion_mm: float) -> tuple[np.ndarray, np.ndarray]: ...
