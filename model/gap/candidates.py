"""Candidate effects: fit each on the training recordings, evaluate on held-out, rank them.

Every candidate is fitted the same way, whatever it is: its 1-3 parameters jointly with the
base parameters on the training recordings (`run_task`); then its held-out tip RMSE is
compared with the baseline's. The fits are independent and run in parallel processes.

Ranking score (higher is better):

    score = shrink - PARAMETER_PENALTY * n_params + SIGNATURE_WEIGHT * match

shrink = 1 - RMSE_after / RMSE_before on the selection half of the held-out data
(`model.gap.holdout_split`); match = cosine between the candidate's correction
c = tip_candidate - tip_baseline and the baseline's residual -e = tip_measured - tip_baseline
over the same samples (1: the candidate moves the tip exactly the way the residual points; 0:
unrelated). The same RMSE and shrink on the report half are kept beside them: those are the
numbers the diagnosis publishes. A candidate whose held-out prediction failed (the model
diverged or crawled: infinite errors) scores -inf. Whether the best is a found effect is
decided in `model.gap.significance` and `model.gap.plausibility`.

Each fit also reports its ablation: the same base parameters with the effect switched off. If
that is as good, the fit improved on the baseline by refitting, not through the effect, and
the ablation is a better baseline.
"""
from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Executor, as_completed
from dataclasses import dataclass

import numpy as np

from model.effects.catalog import effect
from model.gap.calibration import (MIN_ITERATION_LIMIT, ZERO_OFFSETS_MM, ModelFit, calibrate, explore,
                                   iteration_limit, probe_costs, rmse_mm, tip_errors)
from model.gap.holdout_split import HoldoutSplit
from model.gap.recording import Recording
from model.gap.simulation import Resolution, catheter_for
from model.gap.starting_points import probe_values, start_values
from model.params import CatheterParams

PARAMETER_PENALTY = 0.005   # shrink charged per added parameter
SIGNATURE_WEIGHT = 0.02     # score bonus for a correction that points where the residual does
CANDIDATE_ITERATIONS = 15
FINAL_FITS = 2              # explored starts fitted to the end (EXPLORE); the lower training RMSE is kept


@dataclass(frozen=True)
class CandidateResult:
    """One fitted effect set: fit, held-out errors, RMSE, shrink, match and score.

holdout_rmse_mm, shrink, signature_match and score: on the selection half of the held-out
samples; report_rmse_mm and report_shrink: on the report half (see module doc).

    ablated_*: the fit's base parameters with the effects switched off (training RMSE and
    held-out errors; inf and () when not computed).

    started_from: the base-only fit it started from, "calibration" or "better baseline" (see
    `model.gap.diagnosis.better_start`); train_rmse_mm_by_start: the training RMSE the fit reached
    from each start, where it was fitted from both (empty otherwise); a control refit of the
    verdict's effect may go lower still.
    """

    effects: tuple[str, ...]
    fit: ModelFit
    holdout_rmse_mm: float
    holdout_errors: tuple[np.ndarray, ...]
    shrink: float
    signature_match: float
    score: float
    report_rmse_mm: float
    report_shrink: float
    seconds: float = 0.0
    ablated_train_rmse_mm: float = math.inf
    ablated_holdout_errors: tuple[np.ndarray, ...] = ()
    started_from: str = "calibration"
    train_rmse_mm_by_start: dict = dataclasses.field(default_factory=dict)

    @property
    def failed(self) -> bool:
        """Its held-out prediction failed (diverged or over its iteration limit) on some sample."""
        return not all(np.isfinite(e).all() for e in self.holdout_errors)

    @property
    def n_params(self) -> int:
        return sum(len(effect(effect_id).param_names) for effect_id in self.effects)

    def ablated(self) -> ModelFit:
        """The base parameters of this fit without its effects."""
        return ModelFit(self.fit.params, self.fit.zero_offsets_mm, {}, train_rmse_mm=self.ablated_train_rmse_mm)

    def as_dict(self) -> dict:
        """Plain JSON-able summary; a model that diverged on held-out data has None for its numbers."""
        def number(value: float) -> float | None:
            return float(value) if np.isfinite(value) else None

        params = self.fit.effect_params()
        return {"effect": "+".join(self.effects) if self.effects else "none", "effects": list(self.effects),
                "params": params if len(self.effects) != 1 else params[self.effects[0]],
                "n_params": self.n_params, "train_rmse_mm": number(self.fit.train_rmse_mm),
                "holdout_rmse_mm": number(self.report_rmse_mm), "shrink": number(self.report_shrink),
                "selection_rmse_mm": number(self.holdout_rmse_mm), "selection_shrink": number(self.shrink),
                "signature_match": number(self.signature_match), "score": number(self.score),
                "ablated_train_rmse_mm": number(self.ablated_train_rmse_mm),
                "ablated_holdout_rmse_mm": number(rmse_mm(self.ablated_holdout_errors))
                if self.ablated_holdout_errors else None,
                "diverged": self.failed, "flags": list(self.fit.flags),
                "model_runs": self.fit.model_runs, "seconds": self.seconds, "started_from": self.started_from,
                "train_rmse_mm_by_start": {start: number(rmse) for start, rmse in self.train_rmse_mm_by_start.items()}}


EXPLORE = "explore"     # single candidates and the plain refit: four starts, explored
PROBE = "probe"         # a second effect: probed from the start's base parameters
CONTINUE = "continue"   # a control: the start as given


@dataclass(frozen=True)
class FitTask:
    """Everything one worker needs to fit and evaluate one effect set (picklable)."""

    effects: dict[str, tuple[float, ...]]
    start: ModelFit
    prior: CatheterParams
    train: tuple[Recording, ...]
    holdout: tuple[Recording, ...]     # already at the fit resolution
    baseline_errors: tuple[np.ndarray, ...]
    split: HoldoutSplit
    resolution: Resolution
    iterations: int = CANDIDATE_ITERATIONS
    mode: str = EXPLORE

    @property
    def prepared_train(self) -> list[Recording]:
        return self.resolution.prepare_training(self.train)


def run_task(task: FitTask) -> CandidateResult:
    """Fit the task's effects with the base parameters, evaluate on held-out data, ablate.

    The last effect of the task is the one being added. Where its fit starts depends on the mode:
    - EXPLORE: four starts, each explored by a short fit, the FINAL_FITS best then fitted to the
      end: the continuation (the start fit, e.g. the baseline, with the effect off), the same with
      the effect at the probe value that fits the training data best (one model run each), and
      two fresh starts, zero tendon zeros with the start's or the prior's other parameters, each
      with its best probe value. A baseline that lacks an effect has bent its parameters (its
      tendon zeros bend the catheter at rest in place of gravity or precurvature, its friction
      imitates backlash, slack tendons and a stiff shaft imitate tendon elasticity), and the
      continuation can stall there while still looking best after a short fit: in two blind
      cases (tendon elasticity, precurvature) it explored to 0.39 and 0.55 mm against 0.43 and
      1.29 mm for a fresh start, which then fitted to 0.29 and 0.25 mm against 0.39 and 0.52 mm.
    - PROBE: the start fit with the effect at its best probe value.
    - CONTINUE: the start fit and effect values as given.
    """
    clock = time.perf_counter()
    fixed = dict(task.effects)
    last = list(fixed)[-1] if fixed else None
    train = task.prepared_train
    probes = probe_values(last) if last else [()]

    def with_last(params: CatheterParams, zeros, value) -> ModelFit:
        return ModelFit(params, tuple(zeros), {**fixed, last: value} if last else {})

    start = task.start
    if task.mode == EXPLORE:
        candidates = [with_last(start.params, start.zero_offsets_mm, start_values(last) if last else ())]
        for base, zeros in ((start.params, start.zero_offsets_mm), (start.params, ZERO_OFFSETS_MM),
                            (catheter_for(task.prior, train), ZERO_OFFSETS_MM)):
            probed = [with_last(base, zeros, probe) for probe in probes]
            candidates.append(probed[int(np.argmin(probe_costs(probed, train, task.resolution)))])
        unique = [c for i, c in enumerate(candidates) if c not in candidates[:i]]   # a probe may pick 'off'
        finals = explore(task.train, unique, task.prior, task.resolution)[:FINAL_FITS]
    elif task.mode == PROBE:
        probed = [with_last(start.params, start.zero_offsets_mm, probe) for probe in probes]
        finals = [probed[int(np.argmin(probe_costs(probed, train, task.resolution)))]]
    else:
        finals = [ModelFit(start.params, start.zero_offsets_mm, fixed)]
    fit = min((calibrate(task.train, final.params, prior=task.prior, zero_offsets_mm=final.zero_offsets_mm,
                         effects=final.effects, resolution=task.resolution, max_iterations=task.iterations)
               for final in finals), key=lambda candidate: candidate.train_rmse_mm)
    train_limit = iteration_limit(task.start, train, task.resolution)
    holdout_limit = holdout_iteration_limit(train_limit, iteration_limit(fit, train, task.resolution), train,
                                            task.holdout)
    errors = tuple(tip_errors(fit, task.holdout, task.resolution, holdout_limit))
    result = evaluate(tuple(task.effects), fit, errors, task.baseline_errors, task.split)
    ablated = ModelFit(fit.params, fit.zero_offsets_mm, {})
    return dataclasses.replace(
        result, seconds=time.perf_counter() - clock,
        ablated_train_rmse_mm=rmse_mm(tip_errors(ablated, train, task.resolution, train_limit)),
        ablated_holdout_errors=tuple(tip_errors(ablated, task.holdout, task.resolution, holdout_limit)))


def holdout_iteration_limit(start_limit: int, fit_limit: int, train: Sequence[Recording],
                            holdout: Sequence[Recording]) -> int:
    """Newton iterations a fit's held-out run (and its ablation's) may take before it is given up (inf).

    The fit's end point may be where the solver crawls: give up on it, as a fit does, at
    SLOW_RUN_FACTOR x a normal run's iterations (the limits `iteration_limit` gives). A normal run is
    the start's or the fit's own on the training recordings, whichever took more: a drive line of
    0.09 mm/N makes every step of the model take more Newton iterations, and with the start's alone a
    tendon elasticity fitted within 16 % of the truth (rod seed 60) needed 17,172 on its held-out log
    against a limit of 14,411, and was never a verdict. A run costs in proportion to its samples, so
    the limit is scaled by held-out over training samples:

        limit = max(start_limit, fit_limit) * n_holdout / n_train   (at least MIN_ITERATION_LIMIT)
    """
    scale = sum(map(len, holdout)) / sum(map(len, train))
    return max(int(max(start_limit, fit_limit) * scale), MIN_ITERATION_LIMIT)


def evaluate(effects: tuple[str, ...], fit: ModelFit, errors: Sequence[np.ndarray],
             baseline_errors: Sequence[np.ndarray], split: HoldoutSplit) -> CandidateResult:
    """Held-out RMSE, shrink, signature match and score of a fitted effect set (see module doc)."""
    def rmse_and_shrink(part: Callable[[Sequence[np.ndarray]], list[np.ndarray]]) -> tuple[float, float]:
        before, after = rmse_mm(part(baseline_errors)), rmse_mm(part(errors))
        if not np.isfinite(after):
            return math.inf, -math.inf
        return after, 1.0 - after / before if before > 0 else 0.0

    holdout_rmse, shrink = rmse_and_shrink(split.selected)
    report_rmse, report_shrink = rmse_and_shrink(split.reported)
    e = np.concatenate(split.selected(baseline_errors)).ravel()
    c = np.concatenate(split.selected(errors)).ravel() - e
    norm = np.linalg.norm(c) * np.linalg.norm(e)
    match = float(-(c @ e) / norm) if np.isfinite(norm) and norm > 0 else 0.0
    n_params = sum(len(effect(effect_id).param_names) for effect_id in effects)
    score = shrink - PARAMETER_PENALTY * n_params + SIGNATURE_WEIGHT * match
    return CandidateResult(effects, fit, holdout_rmse, tuple(errors), shrink, match, score, report_rmse,
                           report_shrink)


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


def ranked(results: Sequence[CandidateResult]) -> list[CandidateResult]:
    """Best score first (a failed prediction, score -inf or NaN, last)."""
    return sorted(results, key=lambda result: -result.score if np.isfinite(result.score) else math.inf)
