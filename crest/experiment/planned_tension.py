"""The pre-motion tension check of `crest move` and `crest run`: a planned path, against each tendon's limit."""
from __future__ import annotations

import numpy as np

from control.path_tension import DEFAULT_TENSION_MARGIN, check_path_tension, forecast_path_tension
from crest.config import TestbedConfig
from crest.driver import AxisTargets
from model import CatheterParams


def check_planned_tension(config: TestbedConfig, params: CatheterParams, start: AxisTargets, tendon_mm,
                          insertion_mm, what: str, remedy: str, n_elements: int = 20) -> None:
    """Refuse (control.path_tension.TensionLimitError) before motion when the controller's model
    predicts that the path from `start` through tendon_mm (T, 4), insertion_mm (T,) needs more than
    max_tension_n / (1 + DEFAULT_TENSION_MARGIN) on any tendon axis; `remedy` tells the operator what to change."""
    tendons = np.vstack([np.asarray(start.tendon_mm, dtype=float), np.asarray(tendon_mm, dtype=float).reshape(-1, 4)])
    lengths = np.concatenate([[float(start.insertion_mm)], np.asarray(insertion_mm, dtype=float).reshape(-1)])
    forecast = forecast_path_tension(params, tendons, lengths, n_elements)
    axes = config.tendon_axes
    check_path_tension(forecast, [a.max_tension_n for a in axes], [a.name for a in axes], what,
                       DEFAULT_TENSION_MARGIN, remedy)
