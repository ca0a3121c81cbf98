"""Put a controller's model where the catheter rests when a run begins."""
from __future__ import annotations

import numpy as np

from model import DahlCatheter


def reset_straight(model: DahlCatheter, insertion_mm: float | None = None) -> None:
    """Straight, unloaded, zero friction state, tendons at 0 mm, at this free length (default: the params')."""
    model.reset()
    if insertion_mm is not None:
        model.move_to(np.zeros(4), insertion_mm)
