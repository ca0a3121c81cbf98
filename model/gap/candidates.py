"""Candidate effects: fit each on the training recordings, evaluate on held-out, rank them.

Every candidate is fitted the same way, whatever it is: its 1-3 parameters jointly with the
base parameters, warm-started from the baseline calibration, on the training recordings;
then its held-out tip RMSE is compared with the baseline's. The fits are independent and run
in parallel processes.

Ranking score (higher is better):

    score = shrink - PARAMETER_PENALTY * n_params + SIGNATURE_WEIGHT * match

shrink = 1 - RMSE_after / RMSE_before on held-out data; match = cosine between the
candidate's correction c = tip_candidate - tip_baseline and the baseline's residual
-e = tip_measured - tip_baseline over all held-out samples (1: the candidate moves the tip
exactly the way the residual points; 0: unrelated). A candidate is meaningful only if it
removes more than the noise can explain (`is_meaningful`).
"""
from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Executor, as_completed
from dataclasses import dataclass

import numpy as np

from model.effects.catalog import effect
from model.gap.calibration import MIN_TIME_LIMIT_S, SLOW_RUN_FACTOR, ModelFit, calibrate, rmse_mm, tip_errors
from model.gap.recording import Recording
from model.gap.simulation import Resolution, catheter_for
from model.params import CatheterParams

PARAMETER_PENALTY = 0.005   # shrink charged per added parameter
SIGNATURE_WEIGHT = 0.02     # score bonus for a correction that points where the residual does
MIN_SHRINK = 0.03           # a meaningful effect removes at least 3 % of the held-out RMSE ...
MIN_SHRINK_WITHOUT_NOISE = 0.05   # ... or 5 % when the noise floor is unknown
MIN_GAIN_OVER_NOISE = 0.1   # ... and at least 10 % of the noise variance 3 sigma^2 (mm^2)
MIN_EXCESS_FRACTION = 0.25  # ... and a quarter of the squared error above the noise floor
CANDIDATE_ITERATIONS = 15
EXPLORE_ITERATIONS = 3       # cost evaluations of each start's exploratory fit


@dataclass(frozen=True)
class CandidateResult:
    """One fitted effect set: fit, held-out RMSE and held-out errors, shrink, match and score."""

    effects: tuple[str, ...]
    fit: ModelFit
    holdout_rmse_mm: float
    holdout_errors: tuple[np.ndarray, ...]
    shrink: float
    signature_match: float
    score: float
    seconds: float = 0.0

    @property
    def n_params(self) -> int:
        return sum(len(effect(effect_id).param_names) for effect_id in self.effects)

    def as_dict(self) -> dict:
        """Plain JSON-able summary; a model that diverged on held-out data has None for its numbers."""
        def number(value: float) -> float | None:
            return float(value) if np.isfinite(value) else None

        params = self.fit.effect_params()
        return {"effect": "+".join(self.effects) if self.effects else "none", "effects": list(self.effects),
                "params": params if len(self.effects) != 1 else params[self.effects[0]],
                "n_params": self.n_params, "train_rmse_mm": number(self.fit.train_rmse_mm),
                "holdout_rmse_mm": number(self.holdout_rmse_mm), "shrink": number(self.shrink),
                "signature_match": self.signature_match, "score": number(self.score),
                "diverged": not np.isfinite(self.holdout_rmse_mm), "flags": list(self.fit.flags),
                "model_runs": self.fit.model_runs, "seconds": self.seconds}


def start_values(effect_id: str) -> tuple[float, ...]:
    """The candidate switched off: 0 where 0 is in range, else its typical value."""
    candidate = effect(effect_id)
    return tuple(0.0 if low <= 0.0 <= high else typ
                 for typ, low, high in zip(candidate.typical, candidate.lower, candidate.upper))


def probe_values(effect_id: str) -> list[tuple[float, ...]]:
    """Starting points worth one model run each.

    Off; then for effects with one-sided parameters 1/4, 1/2 and all of the typical values;
    for signed ones (directions) each parameter alone at -+1/2 and -+1 of the typical
    magnitude (three-parameter effects: -+1 only).
    """
    candidate = effect(effect_id)
    off = start_values(effect_id)
    probes = [off]
    if min(candidate.lower) >= 0:
        for fraction in (0.25, 0.5, 1.0):
            probes.append(tuple(o + fraction * (t - o) for o, t in zip(off, candidate.typical)))
        return probes
    magnitude = float(np.linalg.norm(candidate.typical))
    fractions = (1.0,) if len(candidate.param_names) == 3 else (0.5, 1.0)
    for k in range(len(off)):
        for value in (magnitude * f * s for f in fractions for s in (1.0, -1.0)):
            probe = list(off)
            probe[k] = float(np.clip(value, candidate.lower[k], candidate.upper[k]))
            probes.append(tuple(probe))
    return probes


@dataclass(frozen=True)
class FitTask:
    """Everything one worker needs to fit and evaluate one effect set (picklable)."""

    effects: dict[str, tuple[float, ...]]
    start: ModelFit
    prior: CatheterParams
    train: tuple[Recording, ...]
    holdout: tuple[Recording, ...]     # already at the fit resolution
    baseline_errors: tuple[np.ndarray, ...]
    baseline_rmse_mm: float
    resolution: Resolution
    iterations: int = CANDIDATE_ITERATIONS
    explore: bool = True    # False: fit from the start as given (pairs, controls)

    @property
    def prepared_train(self) -> list[Recording]:
        return self.resolution.prepare_training(self.train)


def run_task(task: FitTask) -> CandidateResult:
    """Fit the task's effects with the base parameters and evaluate them on the held-out data.

    With `explore` (single candidates), two starts, each explored by a short fit, the better one
    then fitted to the end (otherwise the fit starts from the task's start and effect values):
    - continuation: the starting fit (baseline) with the new effect off;
    - fresh: the prior catheter with zero tendon zeros and the new effect at its best probe
      value (`probe_values`, one model run each). A baseline that lacks an effect has bent its
      parameters (e.g. its tendon zeros bend the catheter at rest in place of precurvature),
      and the continuation can stall there.
    """
    clock = time.perf_counter()
    fixed = dict(task.effects)
    last = list(fixed)[-1] if fixed else None
    if task.explore:
        train = task.prepared_train
        prior = ModelFit(catheter_for(task.prior, train), (0.0, 0.0, 0.0, 0.0), {})
        continuation = (task.start, {**fixed, last: start_values(last)} if last else {})
        fresh_starts = [{**fixed, last: probe} if last else {} for probe in (probe_values(last) if last else [()])]
        costs = _probe_costs([ModelFit(prior.params, prior.zero_offsets_mm, effects) for effects in fresh_starts],
                             train, task.resolution)
        fresh = (prior, fresh_starts[int(np.argmin(costs))])
        explored = [calibrate(task.train, base.params, prior=task.prior, zero_offsets_mm=base.zero_offsets_mm,
                              effects=effects, resolution=task.resolution, max_iterations=EXPLORE_ITERATIONS,
                              restarts=0) for base, effects in (continuation, fresh)]
        best = min(explored, key=lambda fit: fit.train_rmse_mm)
    else:
        best = ModelFit(task.start.params, task.start.zero_offsets_mm, fixed)
    fit = calibrate(task.train, best.params, prior=task.prior, zero_offsets_mm=best.zero_offsets_mm,
                    effects=best.effects, resolution=task.resolution, max_iterations=task.iterations)
    errors = tuple(tip_errors(fit, task.holdout, task.resolution))
    result = evaluate(tuple(task.effects), fit, errors, task.baseline_errors, task.baseline_rmse_mm)
    return dataclasses.replace(result, seconds=time.perf_counter() - clock)


def _probe_costs(fits: Sequence[ModelFit], train: Sequence[Recording], resolution: Resolution) -> list[float]:
    """Training RMSE of each fit; runs slower than SLOW_RUN_FACTOR x the first are given up (inf)."""
    clock = time.perf_counter()
    costs = [rmse_mm(tip_errors(fits[0], train, resolution))]
    limit = max(SLOW_RUN_FACTOR * (time.perf_counter() - clock), MIN_TIME_LIMIT_S)
    return costs + [rmse_mm(tip_errors(fit, train, resolution, limit)) for fit in fits[1:]]


def evaluate(effects: tuple[str, ...], fit: ModelFit, errors: Sequence[np.ndarray],
             baseline_errors: Sequence[np.ndarray], baseline_rmse_mm: float) -> CandidateResult:
    """Held-out RMSE, shrink, signature match and score of a fitted effect set."""
    holdout_rmse = rmse_mm(errors)
    shrink = 1.0 - holdout_rmse / baseline_rmse_mm if baseline_rmse_mm > 0 else 0.0
    e = np.concatenate(baseline_errors).ravel()
    c = np.concatenate(errors).ravel() - e
    norm = np.linalg.norm(c) * np.linalg.norm(e)
    match = float(-(c @ e) / norm) if np.isfinite(norm) and norm > 0 else 0.0
    n_params = sum(len(effect(effect_id).param_names) for effect_id in effects)
    score = shrink - PARAMETER_PENALTY * n_params + SIGNATURE_WEIGHT * match
    return CandidateResult(effects, fit, holdout_rmse, tuple(errors), shrink, match, score)


def run_tasks(tasks: Sequence[FitTask], executor: Executor | None = None,
              on_done: Callable[[CandidateResult], None] | None = None) -> list[CandidateResult]:
    """Run the fits on the executor's workers (here, one after the other, without one); results in task order."""
    if executor is None:
        results = []
        for task in tasks:
            results.append(run_task(task))
            if on_done is not None:
                on_done(results[-1])
        return results
    results: list[CandidateResult | None] = [None] * len(tasks)
    futures = {executor.submit(run_task, task): index for index, task in enumerate(tasks)}
    for future in as_completed(futures):
        results[futures[future]] = future.result()
        if on_done is not None:
            on_done(results[futures[future]])
    return results


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


def ranked(results: Sequence[CandidateResult]) -> list[CandidateResult]:
    """Best score first."""
    return sorted(results, key=lambda result: -result.score)
