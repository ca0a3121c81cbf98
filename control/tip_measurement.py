"""One tip sample from the tracker, as control sees it."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class TipMeasurement:
    """tip_mm: (3,) measured tip in the catheter base frame.
    time_s: when the tracker took it, on the same clock as SetPoint.t_s. A sample whose time
    does not advance is a repeat, one older than the estimator's max age is stale.
    """

    tip_mm: np.ndarray
    time_s: float
