"""Calibrate and diagnose from log files: the path `crest fit`, `crest gap` and the blind benchmark share.

Only the files are seen: what produced them (hardware, virtual testbed, a model plant with a
hidden effect) is not an input.
"""
from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from concurrent.futures import Executor
from pathlib import Path

from crest.gap.fit_executor import local_executor
from crest.gap.log_recordings import load_recordings
from model import CatheterParams
from model.gap.calibration import (FAST_TENDON_SPEED_MM_S, ModelFit, calibrate_base, fast_travel_share, is_fast,
                                   rmse_mm, tip_errors)
from model.gap.diagnosis import DiagnosisSettings, diagnose
from model.gap.force_scale import scaled_to_tensions
from model.gap.free_parameters import ParameterLayout
from model.gap.simulation import catheter_for


def prior_catheter(catheter_toml: Path | str | None) -> CatheterParams:
    """The starting catheter: the given TOML or configs/catheter.toml."""
    return CatheterParams.from_toml(catheter_toml) if catheter_toml else CatheterParams.from_toml()


def calibrate_logs(train: Sequence[Path | str], catheter_toml: Path | str | None = None,
                   settings: DiagnosisSettings = DiagnosisSettings(),
                   progress: Callable[[str], None] | None = None, fit_dynamics: bool | None = False) -> ModelFit:
    """Fit the base model to the training logs (geometry from their sidecars), then set its force
    scale from the logs' drive tensions where they have them (`model.gap.force_scale`: the tips do
    not fix it, a controller planning tensions needs it); the training RMSE and flags are those of
    the rescaled model.

    fit_dynamics: also fit the damping time and inertia scale; None: when the logs are fast
    (model.gap.calibration.is_fast).
    """
    prior = prior_catheter(catheter_toml)
    recordings = load_recordings(train)
    say = progress or (lambda message: None)
    if fit_dynamics is None:
        fit_dynamics = is_fast(recordings)
        say(f"{100 * fast_travel_share(recordings):.0f}% of the tendon travel at >= "
            f"{FAST_TENDON_SPEED_MM_S:g} mm/s: "
            + ("fast, fitting the damping time and inertia scale too" if fit_dynamics else "quasi-static fit"))
    with local_executor(settings.workers) as pool:
        fit = calibrate_base(recordings, prior, resolution=settings.resolution,
                             max_iterations=settings.baseline_iterations, executor=pool,
                             on_fit=lambda done, total: say(f"base model: {done}/{total} starts fitted"),
                             fit_dynamics=fit_dynamics)
    prepared = settings.resolution.prepare_training(recordings)
    scaled = scaled_to_tensions(fit, prepared, settings.resolution)
    if scaled is None:
        say("the logs hold no drive tensions: the force scale (EI, EA, sigma and Fsc together) is left where "
            "the tip fit ended; the tips do not fix it")
        return fit
    fit, scale = scaled
    say(f"force scale from the logged drive tensions: x{scale:.3f} on EI, EA, sigma and Fsc"
        + (" and the inertia scale" if fit_dynamics else ""))
    flags = ParameterLayout(catheter_for(prior, prepared), (), True, fit_dynamics).flags(fit.values)
    return dataclasses.replace(fit, flags=flags, train_rmse_mm=rmse_mm(tip_errors(fit, prepared, settings.resolution)))


def diagnose_logs(train: Sequence[Path | str], holdout: Sequence[Path | str],
                  catheter_toml: Path | str | None = None, settings: DiagnosisSettings = DiagnosisSettings(),
                  progress: Callable[[str], None] | None = None, executor: Executor | None = None) -> dict:
    """The gap diagnosis (model.gap.diagnosis.diagnose) of training and held-out logs; executor: where
    the fits run (default: local processes, see `crest.gap.fit_executor`)."""
    return diagnose(load_recordings(train), load_recordings(holdout), prior_catheter(catheter_toml), settings,
                    progress, executor)
