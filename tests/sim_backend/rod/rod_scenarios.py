"""Drive inputs and plants shared by the rod plant's tests."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from sim_backend.plant.rod import RodDescription, RodPlant

FREE_LENGTH_MM = 80.0
DT_S = 0.01


def description(**changes) -> RodDescription:
    """configs/rod_plant.toml with these fields changed."""
    return replace(RodDescription.from_toml(), **changes)


def pull(plant: RodPlant, pull_mm: float, free_length_mm: float = FREE_LENGTH_MM):
    """Tendon 1 pulled by pull_mm, tendon 3 paid out by as much (the antagonist never pushes)."""
    return plant.step(DT_S, [pull_mm, 0.0, -pull_mm, 0.0], free_length_mm)


def ramp(plant: RodPlant, start_mm: float, stop_mm: float, steps: int = 100) -> list[tuple[np.ndarray, np.ndarray]]:
    return [pull(plant, u) for u in np.linspace(start_mm, stop_mm, steps)]
