"""What a controller sends to the drives in one SYNC period."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class TendonCommand:
    """tendon_mm: (4,) tendon displacements, positive = pulled, pretension included.
    insertion_mm: free length out of the support tube.
    predicted_tip_mm: (3,) the tip the controller's model expects after this command.
    saturated: a range or velocity limit cut the command this cycle.
    """

    tendon_mm: np.ndarray
    insertion_mm: float
    predicted_tip_mm: np.ndarray
    saturated: bool = False
