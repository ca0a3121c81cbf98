"""The part of an effect that the calibrated model cannot take up: what a diagnosis can see of it.

An effect moves the plant's tip by its raw size (`blind_benchmark.rod_effect_rms_mm`), but the
base model's parameters can absorb part of that: a soft proximal sheath (the rod's lumen
compression) looks, on the tips, like a catheter of other stiffnesses. Calibrated on the log,
the base model leaves only the rest in its residual, and only that rest can name an effect.

With two recordings of the same commands, one of the plant with the effect and one of the same
plant without it (the rod family's plain held-out log), the base model is calibrated on each
log itself (in-sample: the best it can do there) and

    visible = sqrt(max(r_with^2 - r_plain^2, 0)),

r the in-sample tip RMSE. Both residuals hold the same model form and the same level of tracker
noise, so the difference of squares is what the effect adds that no base parameter can follow.
No candidate fit enters it, so it does not share the candidate search's failures.
"""
from __future__ import annotations

import math
from concurrent.futures import Executor

from model.gap.calibration import calibrate_base
from model.gap.diagnosis import DiagnosisSettings
from model.gap.recording import Recording
from model.params import CatheterParams


def visible_effect_mm(with_effect: Recording, plain: Recording, prior: CatheterParams,
                      settings: DiagnosisSettings = DiagnosisSettings(), executor: Executor | None = None) -> float:
    """sqrt(max(r_with^2 - r_plain^2, 0)) [mm], each r the in-sample RMSE of the base model calibrated
    (as the diagnosis calibrates its baseline) on that recording alone."""
    with_rmse, plain_rmse = (calibrate_base([recording], prior, resolution=settings.resolution,
                                            max_iterations=settings.baseline_iterations,
                                            executor=executor).train_rmse_mm
                             for recording in (with_effect, plain))
    return math.sqrt(max(with_rmse ** 2 - plain_rmse ** 2, 0.0))
