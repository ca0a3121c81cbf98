"""When is a smaller held-out error a found effect, and not noise or fitting freedom?

The held-out tip RMSE of a model is at best the tracker noise floor f = sqrt(3) sigma (sigma
per axis, `model.gap.noise`). An added effect must remove a part of the error above that
floor that no amount of refitting noise could: see `is_meaningful`.
"""
from __future__ import annotations

import numpy as np

MIN_SHRINK = 0.03                 # at least 3 % of the held-out RMSE ...
MIN_SHRINK_WITHOUT_NOISE = 0.05   # ... or 5 % when the noise floor is unknown
MIN_GAIN_OVER_NOISE = 0.1         # ... and at least 10 % of the noise variance 3 sigma^2 (mm^2)
MIN_EXCESS_FRACTION = 0.25        # ... and a quarter of the squared error above the noise floor


def is_meaningful(rmse_before_mm: float, rmse_after_mm: float, noise_mm: float | None) -> bool:
    """Does going from before to after remove more error than noise and fitting freedom explain?

    With the noise floor f^2 = 3 sigma^2 (sigma per axis) the gain g = before^2 - after^2 must
    reach MIN_GAIN_OVER_NOISE * f^2 and MIN_EXCESS_FRACTION of the excess before^2 - f^2 (the part
    of the error a model could remove at all), and the shrink 1 - after/before MIN_SHRINK.
    Without a noise estimate: shrink >= MIN_SHRINK_WITHOUT_NOISE.
    """
    if not (rmse_before_mm > 0 and np.isfinite(rmse_after_mm)):
        return False
    shrink = 1.0 - rmse_after_mm / rmse_before_mm
    if noise_mm is None:
        return shrink >= MIN_SHRINK_WITHOUT_NOISE
    floor = 3.0 * noise_mm ** 2
    gain = rmse_before_mm ** 2 - rmse_after_mm ** 2
    return shrink >= MIN_SHRINK and gain >= max(MIN_GAIN_OVER_NOISE * floor,
                                                MIN_EXCESS_FRACTION * (rmse_before_mm ** 2 - floor))


RESIDUAL_EXCESS = 0.3             # a residual is significant when its squared RMSE exceeds the floor by 30 %


def is_significant_residual(rmse_mm: float, noise_mm: float | None) -> bool:
    """Is a held-out error more than the tracker noise can explain: rmse^2 >= (1 + RESIDUAL_EXCESS) f^2
    with f^2 = 3 sigma^2 (rmse >= 1.14 f)? Without a noise estimate the data cannot tell: False.

    Since every log starts with no friction stored (`control.excitation`, f7f6e4e), the Dahl
    family's clean cases leave 0.96-1.13 floors on the selection half (eleven cases of seeds 55-73:
    nine re-recorded, seed 73's two), where before their first static hold's tip offset put them at
    up to 1.24 and let a precurvature absorb it. Three true effects recorded then (two elastic lines
    and a rate lag at 1.17-1.20 floors, whose fits removed 0.14-0.24 of the error) were refused by
    the margin of 0.5 (1.22 floors) that had been set with the offset in the logs.
    """
    if noise_mm is None or not np.isfinite(rmse_mm):
        return False
    return rmse_mm ** 2 >= (1.0 + RESIDUAL_EXCESS) * 3.0 * noise_mm ** 2


def nothing_to_explain(rmse_mm: float, noise_mm: float | None) -> str | None:
    """Why no effect may be named on a baseline whose held-out error is `rmse_mm` (None: there is
    something to explain): its error is within the tracker noise (`is_significant_residual` fails).
    Without a noise estimate the data cannot tell, and nothing is ruled out here."""
    if noise_mm is None or is_significant_residual(rmse_mm, noise_mm):
        return None
    return (f"nothing significant to explain: the baseline's {rmse_mm:.3f} mm is within the tracker noise "
            f"(floor {np.sqrt(3.0) * noise_mm:.3f} mm)")


def model_form_rms_mm(rmse_mm: float, noise_mm: float | None) -> float | None:
    """The part of a held-out error above the noise floor, sqrt(max(rmse^2 - f^2, 0)) (mm): what a
    model could remove at all; None without a noise estimate."""
    if noise_mm is None or not np.isfinite(rmse_mm):
        return None
    return float(np.sqrt(max(rmse_mm ** 2 - 3.0 * noise_mm ** 2, 0.0)))
