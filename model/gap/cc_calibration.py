"""Calibrated constant curvature: the reference every calibrated Dahl figure is compared with.

Constant curvature has no friction and no stiffness: its only parameters are geometric. Fitted to
the same training recordings as the Dahl model, by the same least squares over the tip error,

    minimise  sum_t |tip_cc(u(t) - zero; r, L(t)) - tip_measured(t)|^2,

over the tendon offset r (the moment arm, within the same +-40 % of its nominal value as the Dahl
fit) and the tendon zeros. Only antagonistic differences bend a constant-curvature arc,

    theta (cos phi, sin phi) = ((u1 - z1) - (u3 - z3), (u2 - z2) - (u4 - z4)) / (2 r),

so the zeros enter as two bend offsets, z_x = (z1 - z3)/2 and z_y = (z2 - z4)/2 (within the Dahl
fit's +-3 mm), reported as the zeros (z_x, z_y, -z_x, -z_y). A calibrated Dahl model that does not
beat this on held-out data has learnt nothing constant curvature cannot say.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from model.constant_curvature import tip_from_tendons_mm
from model.gap.free_parameters import TENDON_OFFSET_FIT_SPAN, tendon_offset_bounds_mm
from model.gap.recording import Recording
from model.gap.simulation import catheter_for
from model.params import CatheterParams

ZERO_BOUND_MM = 3.0    # the Dahl fit's bound on a tendon zero


@dataclass(frozen=True)
class CCFit:
    """Calibrated constant curvature: geometry and its training tip RMSE [mm]."""

    tendon_offset_mm: float
    zero_offsets_mm: tuple[float, float, float, float]
    train_rmse_mm: float
    at_bound: tuple[str, ...]      # fitted values that ended at a fit bound

    def tip_errors(self, recordings: Sequence[Recording]) -> list[np.ndarray]:
        """Model minus measured tip [n_valid, 3] per recording (as `model.gap.calibration.tip_errors`)."""
        return [(cc_tips_mm(self.tendon_offset_mm, np.asarray(self.zero_offsets_mm), r) - r.tip_mm)[r.valid]
                for r in recordings]

    def as_dict(self) -> dict:
        return {"tendon_offset_mm": self.tendon_offset_mm, "zero_offsets_mm": list(self.zero_offsets_mm),
                "train_rmse_mm": self.train_rmse_mm, "at_bound": list(self.at_bound)}


def cc_tips_mm(tendon_offset_mm: float, zero_offsets_mm: np.ndarray, recording: Recording) -> np.ndarray:
    """[T, 3] constant-curvature tips for the recording's measured inputs, less the tendon zeros."""
    inputs = recording.tendon_mm - zero_offsets_mm
    return np.array([tip_from_tendons_mm(u, length, tendon_offset_mm)
                     for u, length in zip(inputs, recording.insertion_mm)])


def calibrate_constant_curvature(recordings: Sequence[Recording], prior: CatheterParams) -> CCFit:
    """Fit r, z_x, z_y (module doc) to the valid rows of the recordings, from the nominal r (that of
    `catheter_for`, as for the Dahl fit) and zeros 0."""
    geometry = catheter_for(prior, recordings)        # the geometry and offset bounds the Dahl fit uses
    nominal = geometry.tendon_offset_mm
    low_r, high_r = tendon_offset_bounds_mm(nominal, geometry.outer_diameter_mm, TENDON_OFFSET_FIT_SPAN)

    def zeros(z_x: float, z_y: float) -> np.ndarray:
        return np.array([z_x, z_y, -z_x, -z_y])

    def residuals(x: np.ndarray) -> np.ndarray:
        return np.concatenate([(cc_tips_mm(x[0], zeros(x[1], x[2]), r) - r.tip_mm)[r.valid].ravel()
                               for r in recordings])

    lower = np.array([low_r, -ZERO_BOUND_MM, -ZERO_BOUND_MM])
    upper = np.array([high_r, ZERO_BOUND_MM, ZERO_BOUND_MM])
    start = np.array([min(nominal, high_r), 0.0, 0.0])
    solution = least_squares(residuals, start, bounds=(lower, upper), x_scale=np.array([nominal, 1.0, 1.0]))
    x = solution.x
    n_valid = sum(int(r.valid.sum()) for r in recordings)
    rmse = float(np.sqrt(np.sum(solution.fun ** 2) / n_valid))
    names = ("tendon_offset_mm", "tendon_zero_x_mm", "tendon_zero_y_mm")
    at_bound = tuple(name for name, value, lo, hi in zip(names, x, lower, upper)
                     if np.isclose(value, lo, rtol=1e-6, atol=1e-9) or np.isclose(value, hi, rtol=1e-6, atol=1e-9))
    return CCFit(float(x[0]), tuple(float(v) for v in zeros(x[1], x[2])), rmse, at_bound)
