"""The drive tensions' scale: what the logged tensions tell a fit that the tips do not.

Scaling the bending and axial stiffness, the Dahl stiffness and the constant friction by one
factor scales every tension and leaves the tips nearly where they were (`force_scale`), so a fit
to tips alone can end far along that direction. The drives log each tendon's tension. With the
model's drive tensions T_model and the logged T_meas over every sample and tendon where both are
finite, the least-squares factor between them is

    s = sum(T_model * T_meas) / sum(T_model^2),

1 where the model carries the logged tensions' scale. A fit on n tip samples (3n residuals,
sum of squares n * RMSE^2) adds the one residual

    r_scale = sqrt(n) * SCALE_WEIGHT_MM * ln(s),

so its cost is n * (RMSE^2 + (SCALE_WEIGHT_MM * ln s)^2): tensions a factor e off cost as much as
SCALE_WEIGHT_MM more tip error in quadrature. With 0.5 mm, 10 % off costs 0.05 mm (little against
a 0.5 mm residual), a
factor 2 costs 0.35 mm, and the factor 40 a tip-only baseline once took to absorb a rod's elastic
drive line costs 1.8 mm.
"""
from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

SCALE_WEIGHT_MM = 0.5
MIN_TENSION_N = 0.5      # the model must carry some tension for the factor to mean anything


def tension_scale(model_n: Sequence[np.ndarray], measured_n: Sequence[np.ndarray]) -> float | None:
    """s over pairs of model and logged tensions [T, 4] (N); None where no sample has both or the
    model carries almost no tension (max below MIN_TENSION_N)."""
    model, measured = [], []
    for t_model, t_measured in zip(model_n, measured_n):
        both = np.isfinite(t_model) & np.isfinite(t_measured)
        model.append(t_model[both])
        measured.append(t_measured[both])
    t_model, t_measured = np.concatenate(model), np.concatenate(measured)
    if t_model.size == 0 or np.max(np.abs(t_model)) < MIN_TENSION_N:
        return None
    return float(t_model @ t_measured / (t_model @ t_model))


def scale_residual_mm(scale: float | None, n_tip_samples: int) -> float:
    """r_scale = sqrt(n) * SCALE_WEIGHT_MM * ln(s); 0 without a scale, and large where s <= 0 (the model
    pulls where the drives measured slack: as far from the scale as it gets)."""
    if scale is None:
        return 0.0
    return math.sqrt(n_tip_samples) * SCALE_WEIGHT_MM * math.log(max(scale, 1e-3))
