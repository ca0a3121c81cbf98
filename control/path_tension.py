"""The drive tensions a planned path needs, predicted by the controller's catheter model before motion.

A tendon's drive tension grows with the bend it holds and falls with the free length: for an arc
bent by theta over the free length L, moment balance at the base gives

    T_drive ~ (EI theta / (r L)) * exp(mu theta_eff)

(the capstan factor from the friction the tension must overcome on its way to the tip). At the
homed free length of 20 mm a 120 deg bend needs the whole 40 N of a tendon's max_tension_n; at
80 mm it needs 11 N. Rather than this estimate, the forecast drives the Dahl catheter model
(the one the controller uses) along the commanded tendon path from a straight, unloaded catheter
and keeps each tendon's largest drive tension. A path is refused when that peak, raised by
`margin` (the model/catheter mismatch the forecast must cover), exceeds a tendon's limit.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from model import CatheterParams, DahlCatheter

from control.errors import ControlInputError

DEFAULT_TENSION_MARGIN = 0.2   # forecasts must stay below limit / (1 + margin): covers a 10-20 % model mismatch
FORECAST_STEP_MM = 0.1         # the forecast keeps samples at most this far apart in tendon (quasi-static)


class TensionLimitError(ControlInputError):
    """A planned path needs more tendon tension than a tendon's limit allows (refused before motion)."""


@dataclass(frozen=True)
class TensionForecast:
    """peak_n (4,): each tendon's largest predicted drive tension [N] along the path;
    peak_sample (4,): the path sample where it occurs."""

    peak_n: np.ndarray
    peak_sample: np.ndarray


def forecast_path_tension(params: CatheterParams, tendon_mm, insertion_mm, n_elements: int = 20) -> TensionForecast:
    """Drive tensions along the tendon path tendon_mm (T, 4) [mm] at free lengths insertion_mm (T,) [mm].

    The model starts straight and unloaded at the first sample's free length (where a run starts
    after homing) and moves quasi-statically from sample to sample. Samples closer than
    FORECAST_STEP_MM of tendon (and 1 mm of insertion) to the last kept one are skipped, except
    the last; the model sub-steps between kept samples, so the friction history is the same.
    """
    tendons = np.asarray(tendon_mm, dtype=float).reshape(-1, 4)
    lengths = np.asarray(insertion_mm, dtype=float).reshape(-1)
    model = DahlCatheter(params.replace(free_length_mm=float(np.clip(lengths[0], params.min_free_length_mm,
                                                                     params.max_free_length_mm))), n_elements)
    peak = np.zeros(4)
    where = np.zeros(4, dtype=int)
    kept_tendons, kept_length = tendons[0], lengths[0]
    for k in range(len(tendons)):
        last = k == len(tendons) - 1
        if (not last and k > 0 and np.max(np.abs(tendons[k] - kept_tendons)) < FORECAST_STEP_MM
                and abs(lengths[k] - kept_length) < 1.0):
            continue
        kept_tendons, kept_length = tendons[k], lengths[k]
        model.move_to(tendons[k], lengths[k])
        tension = model.drive_tension_n
        higher = tension > peak
        peak[higher] = tension[higher]
        where[higher] = k
    return TensionForecast(peak, where)


def check_path_tension(forecast: TensionForecast, max_tension_n: Sequence[float], tendon_names: Sequence[str],
                       what: str, margin: float = DEFAULT_TENSION_MARGIN,
                       remedy: str = "lower the articulation or use a longer free length") -> None:
    """Raise TensionLimitError naming the tendon, the tension, the limit and the remedy when
    peak * (1 + margin) > max_tension_n for any tendon."""
    for k, (peak, limit) in enumerate(zip(forecast.peak_n, max_tension_n)):
        if peak * (1.0 + margin) > limit:
            raise TensionLimitError(
                f"{what} refused before motion: it needs {peak:.1f} N on {tendon_names[k]} by the controller's model "
                f"({peak * (1.0 + margin):.1f} N with the {margin:.0%} margin), above its max_tension_n "
                f"{limit:g} N; {remedy}")
