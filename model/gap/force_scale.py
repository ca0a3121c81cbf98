"""The force scale that tips leave free, fixed by the logged drive tensions.

Scaling the bending and axial stiffness, the Dahl stiffness sigma and the constant friction Fsc by
one factor s (and, in the dynamic mode, the inertia, so that mass over stiffness stays) scales the
tendon tensions that bending takes by s and leaves the shape nearly as it was: only the tendons'
own stretch (EA_t does not scale) and the pretension they carry in series with the shaft's axial
stiffness do not follow. A fit to tips alone therefore ends almost anywhere along that direction:
on the rod plant's log one start ended at EI 949 N mm^2, another at 1997 with sigma and Fsc twice
as large, 0.002 mm apart in held-out RMSE. Tips are all a diagnosis
compares, but a controller that plans tensions (its tension limit, the testbed's safety stop) needs
the scale: at EI 1997 the 150 deg circle was refused before motion for 39 N on one tendon.

The drives log each tendon's force. The fits already pay for a model whose tensions are off the
logged ones' scale (`tension_scale`), but only in proportion: `crest fit` then puts the fit on that
scale exactly. `rescaled` multiplies the scaled parameters by the least-squares factor s between
the model's and the logged tensions (`tension_scale`).
Since the pretension does not scale, one such step leaves part of the way (a catheter fitted twice
too stiff came back to 1.24 times), so `scaled_to_tensions` repeats it until s is within
SCALE_TOLERANCE of 1.
"""
from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from model.gap.calibration import ModelFit
from model.gap.recording import Recording
from model.gap.simulation import Resolution, predict_tips_and_tension
from model.gap.tension_scale import tension_scale

SCALED = ("bending_stiffness_nmm2", "axial_stiffness_n", "sigma_n_per_mm2", "fsc_n_per_mm", "inertia_scale")
SCALE_TOLERANCE = 0.002
MAX_SCALE_STEPS = 8


def force_scale(fit: ModelFit, recordings: Sequence[Recording], resolution: Resolution) -> float | None:
    """s (`tension_scale`) over the recordings that logged tensions (at the fit resolution: decimated),
    or None where none did or the model holds almost none."""
    logged = [r for r in recordings if r.tendon_force_n is not None]
    if not logged:
        return None
    model = [predict_tips_and_tension(fit.params, fit.terms(), np.asarray(fit.zero_offsets_mm), r, resolution)[1]
             for r in logged]
    return tension_scale(model, [r.tendon_force_n for r in logged])


def rescaled(fit: ModelFit, scale: float) -> ModelFit:
    """The fit with every SCALED parameter (and its std) multiplied by `scale`; the training RMSE and
    flags are the caller's to recompute (the tips move slightly: the tendons' own stretch)."""
    params = fit.params.replace(**{name: scale * getattr(fit.params, name) for name in SCALED})
    values = tuple(scale * v if name in SCALED else v for name, v in zip(fit.names, fit.values))
    std = tuple(scale * s if name in SCALED else s for name, s in zip(fit.names, fit.std))
    return dataclasses.replace(fit, params=params, values=values, std=std)


def scaled_to_tensions(fit: ModelFit, recordings: Sequence[Recording],
                       resolution: Resolution) -> tuple[ModelFit, float] | None:
    """The fit rescaled (`force_scale`, `rescaled`, repeated up to MAX_SCALE_STEPS times) until its drive
    tensions match the logged ones in the least-squares sense, and the total factor; None without tensions."""
    total = 1.0
    for _ in range(MAX_SCALE_STEPS):
        scale = force_scale(fit, recordings, resolution)
        if scale is None:
            return None
        fit, total = rescaled(fit, scale), total * scale
        if abs(scale - 1.0) < SCALE_TOLERANCE:
            break
    return fit, total
