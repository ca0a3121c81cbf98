"""The outer loop of `dahl+fb`: an integral correction of the target on the filtered tip error.

With e_k the filtered tip error (target of the last command minus the estimated tip), gain
k_i, SYNC period T, rate limit v_c and bound c_max, the feedforward aims at target + c_k with

    c_k = clamp_|.|<=c_max( a_k-1 + clip(k_i T e_k, -v_c T, +v_c T) )

Anti-windup by tracking: the integral restarts each cycle from a_k-1 = p_k-1 - target_k-1,
the correction the last command actually realised in the model (p: the model's tip after
the command as sent, i.e. after the inverse's residual and the range and rate limits).
A correction the catheter cannot follow is therefore never accumulated; when the inverse
reaches its target, a = c and this is the plain integrator.
"""
from __future__ import annotations

import math

import numpy as np


class TipCorrection:
    def __init__(self, period_s: float, *, gain_per_s: float = 20.0, max_rate_mm_s: float = 20.0,
                 max_correction_mm: float = 10.0):
        for name, value in dict(period_s=period_s, gain_per_s=gain_per_s, max_rate_mm_s=max_rate_mm_s,
                                max_correction_mm=max_correction_mm).items():
            if not math.isfinite(value) or value <= 0:
                raise ValueError(f"feedback setting {name} must be a finite number > 0, got {value!r}")
        if gain_per_s * period_s > 1.0:
            raise ValueError(f"feedback gain {gain_per_s}/s times the period {period_s} s exceeds 1: the loop would "
                             f"overshoot every cycle; lower gain_per_s")
        self.period_s = float(period_s)
        self.gain_per_s = float(gain_per_s)
        self.max_rate_mm_s = float(max_rate_mm_s)
        self.max_correction_mm = float(max_correction_mm)
        self.reset()

    def reset(self) -> None:
        self.correction_mm = np.zeros(3)

    def update(self, error_mm, realised_mm) -> np.ndarray:
        """One cycle: the filtered error e_k and the correction a_k-1 the last command realised."""
        step = np.clip(self.gain_per_s * self.period_s * np.asarray(error_mm, dtype=float),
                       -self.max_rate_mm_s * self.period_s, self.max_rate_mm_s * self.period_s)
        correction = np.asarray(realised_mm, dtype=float) + step
        size = float(np.linalg.norm(correction))
        if size > self.max_correction_mm:
            correction *= self.max_correction_mm / size
        self.correction_mm = correction
        return correction.copy()
