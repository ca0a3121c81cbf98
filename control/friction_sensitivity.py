"""The model's prediction and its slope with respect to a friction scale, for the state estimator.

A friction scale s multiplies the friction coefficient mu and the constant friction Fsc of
the model (so the Dahl steady-state force Fs = Fsc + Fsv(mu), paper eq. 3, grows about in
proportion). A second model with s = 1 + delta is driven with the same commands as the
controller's, so the whole path history enters the slope:

    d tip / d s ~ (tip(1 + delta) - tip(1)) / delta,   d T_drive / d s likewise.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from model import CatheterParams, DahlCatheter

from control.model_reset import reset_straight


@dataclass(frozen=True)
class ModelPrediction:
    """What the model predicts after a command, at friction scale 1, and its slope in s."""

    tip_mm: np.ndarray                       # (3,)
    drive_tension_n: np.ndarray              # (4,)
    tip_per_friction_scale_mm: np.ndarray    # (3,) d tip / d s
    tension_per_friction_scale_n: np.ndarray  # (4,) d T_drive / d s


class FrictionSensitivity:
    """Carries the model at friction scale 1 + delta alongside the controller's model."""

    def __init__(self, params: CatheterParams, n_elements: int = 20, delta: float = 0.2):
        if not delta > 0:
            raise ValueError(f"friction scale step delta must be > 0, got {delta!r}")
        self.delta = float(delta)
        self.model = DahlCatheter(params.replace(mu=params.mu * (1.0 + delta),
                                                 fsc_n_per_mm=params.fsc_n_per_mm * (1.0 + delta)), n_elements)

    def reset(self, insertion_mm: float | None = None) -> None:
        """Straight and unloaded at this free length, like the controller's model."""
        reset_straight(self.model, insertion_mm)

    def advance(self, tendon_mm: np.ndarray, insertion_mm: float, tip_mm: np.ndarray,
                drive_tension_n: np.ndarray) -> ModelPrediction:
        """Drive the scaled model with the command sent; tip_mm/drive_tension_n are the nominal model's."""
        scaled_tip = self.model.move_to(tendon_mm, insertion_mm)
        return ModelPrediction(np.asarray(tip_mm, dtype=float).copy(), np.asarray(drive_tension_n, dtype=float).copy(),
                               (scaled_tip - tip_mm) / self.delta,
                               (self.model.drive_tension_n - drive_tension_n) / self.delta)
