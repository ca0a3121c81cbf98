"""The gap diagnosis: baseline, where the gap lies, which effect explains it, how far it shrinks.

1. Baseline: calibrate the base model on the training recordings; tip RMSE on training and held-out,
   beside calibrated constant curvature (`cc_calibration`), the reference it must beat.
2. Where: break the held-out residual down by region (`regions`) and compute its signatures.
3. Which: fit every candidate effect (and a plain refit, the control) in parallel, rank them by
   held-out score (`candidates`). Where a base-only fit (the refit, or a candidate with its effect
   switched off) fits the training recordings better than the calibration, it becomes the
   baseline and the best candidates are fitted again from it (`better_start`). The best is chosen only if it removes more than noise can
   explain, both against the baseline and against its own ablation (the same fit with the
   effect switched off), and only if the baseline's error is significant against the tracker
   noise at all; else the verdict is `none` with a description of the unexplained residual.
   Where a found effect with fewer parameters explains about as much (the best is not
   meaningfully better than it), the simplest such effect leads (`simplest_effect`). A second
   effect is added by greedy forward selection among the next best candidates found on their
   own, again only if the pair is meaningful against the control: the chosen effect refitted
   alone with the same budget.
4. How far: held-out RMSE before and after, shrink overall and per region, how the base
   parameters moved when the effect was added, and whether the verdict is most of the gap
   (`verdict_confidence`: confident or partial).
The result is a plain, JSON-able dict (see `diagnose`).
"""
from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from concurrent.futures import Executor
from contextlib import nullcontext
from dataclasses import asdict, dataclass, replace

import numpy as np

from model.effects.catalog import EFFECTS
from model.gap.base_drift import base_drift, describe_drift
from model.gap.calibration import ModelFit, calibrate_base, rmse_mm, tip_errors
from model.gap.cc_calibration import calibrate_constant_curvature
from model.gap.candidates import (CANDIDATE_ITERATIONS, CONTINUE, EXPLORE, PROBE, CandidateResult, FitTask,
                                  evaluate, ranked, run_tasks)
from model.gap.coverage import coverage_lines
from model.gap.finite_json import finite_tree
from model.gap.fit_pool import fit_pool, one_blas_thread
from model.gap.free_parameters import base_values
from model.gap.holdout_split import HoldoutSplit, split_holdout
from model.gap.noise import tracker_noise_mm
from model.gap.plausibility import (hold_drift_reasons, longest_hold_s, range_reasons, signature_concentration,
                                    signature_reasons)
from model.gap.recording import Recording, RecordingError
from model.gap.regions import breakdown, concentrated, regions, shrink_by_region
from model.gap.sample_features import SampleFeatures, compute_features
from model.gap.significance import is_meaningful, is_significant_residual, model_form_rms_mm, nothing_to_explain
from model.gap.signatures import describe, signatures
from model.gap.simplest_effect import as_good_as, parameter_count, simplest_sufficient
from model.gap.simulation import Resolution, predict_tips, predict_tips_and_tension
from model.gap.starting_points import start_values
from model.gap.verdict_confidence import confidence, confidence_line
from model.params import CatheterParams

FORMAT = "crest-gap/2"
UNEXPLAINED = "unexplained"


REFITS_FROM_BETTER_BASE = 3   # candidates fitted again when a base-only fit beats the calibration


@dataclass(frozen=True)
class DiagnosisSettings:
    """How the diagnosis runs. workers: parallel candidate fits; pair_candidates: how many of the
    next best single candidates are tried as a second effect (0: no pairs, single effects only)."""

    resolution: Resolution = Resolution()
    workers: int = 2
    baseline_iterations: int = 40
    candidate_iterations: int = CANDIDATE_ITERATIONS
    pair_candidates: int = 3
    effects: tuple[str, ...] = tuple(EFFECTS)


def diagnose(train: Sequence[Recording], holdout: Sequence[Recording], prior: CatheterParams,
             settings: DiagnosisSettings = DiagnosisSettings(),
             progress: Callable[[str], None] | None = None, executor: Executor | None = None) -> dict:
    """Diagnose the gap between the model (starting from `prior`) and the recordings.

    executor: runs the independent fits (the baseline's starts, the candidates, the pairs); the
    results are taken in submission order, so they do not depend on the executor. Default: a
    process pool of `settings.workers` made here (none for one worker; one BLAS thread per process,
    this one included, see `model.gap.fit_pool`).

    Returns {"format", "baseline", "constant_curvature", "holdout_by_recording", "where", "concentrated",
    "signatures", "candidates", "pairs", "verdict", "coverage", "settings", "sampling", "timing_s"};
    "coverage" lists where the held-out samples leave the training's range (`coverage_lines`); "constant_curvature"
    is the calibrated constant-curvature reference (`cc_calibration`) on the same rows, and
    "holdout_by_recording" the held-out tip RMSE of each held-out recording (all its evaluated rows) for
    constant curvature, the baseline and the baseline with the verdict's effects; "verdict" holds
    "effect" (best id or "none"), "effects" (all selected), "holdout_rmse_before_mm",
    "holdout_rmse_after_mm", "shrink" (0..1) and "confidence" (`verdict_confidence`: "confident" where the
    named effects at least halve the report half's error above the noise floor, "partial" below, None
    when nothing is named) with its "confidence_line", and "as_good" (the found effects the named one does
    not beat by more than noise and fitting freedom explain, `simplest_effect.as_good_as`); "sampling"
    says which rows of the logs the fits and the held-out evaluation used (`Resolution.sampling`:
    decimation, the training cap).
    """
    if not train or not holdout:
        raise RecordingError("the diagnosis needs at least one training and one held-out recording")
    say = progress or (lambda message: None)
    with one_blas_thread():
        if executor is not None:
            return _diagnose(train, holdout, prior, settings, say, executor)
        with fit_pool(settings.workers) if settings.workers > 1 else nullcontext() as pool:
            return _diagnose(train, holdout, prior, settings, say, pool)


def _diagnose(train: Sequence[Recording], holdout: Sequence[Recording], prior: CatheterParams,
              settings: DiagnosisSettings, say: Callable[[str], None], pool: Executor | None) -> dict:
    """The steps of `diagnose` with one worker pool for the baseline's Jacobian, candidates and pairs."""
    res = settings.resolution
    clock = time.perf_counter()
    timing: dict[str, float] = {}
    say(f"baseline: calibrating on {len(train)} training recording(s)")
    baseline = calibrate_base(train, prior, resolution=res, max_iterations=settings.baseline_iterations,
                              executor=pool,
                              on_fit=lambda done, total: say(f"baseline: {done}/{total} starts fitted"))
    held = res.prepare(holdout)
    base_errors = _holdout_errors(baseline, held, res)
    split = split_holdout([len(e) for e in base_errors])
    noise = tracker_noise_mm(list(train) + list(holdout))
    fit_rows = res.prepare_training(train)          # the training rows the fits see
    reference = calibrate_constant_curvature(fit_rows, prior)   # what Dahl must beat
    reference_errors = reference.tip_errors(held)
    timing["baseline"] = time.perf_counter() - clock

    def task(effects: dict, start: ModelFit, mode: str = EXPLORE) -> FitTask:
        return FitTask(effects, start, prior, tuple(train), tuple(held), tuple(base_errors), split, res,
                       settings.candidate_iterations, mode)

    ids = list(settings.effects)
    say(f"candidates: fitting {len(ids)} effects and a plain refit on {settings.workers} worker(s)")
    done = []
    results = run_tasks([task({}, baseline)] + [task({i: start_values(i)}, baseline) for i in ids],
                        pool, lambda r: done.append(r) or say(
                            f"candidates: {len(done)}/{len(ids) + 1} done ({'+'.join(r.effects) or 'refit'})"))
    refit, singles = results[0], results[1:]
    # The baseline is the best base-only model found: the calibration, its plain refit (the control
    # for the candidates' extra fitting effort) or a candidate's fit with its effect switched off.
    bases = [(baseline, base_errors), (refit.fit, list(refit.holdout_errors))] + [
        (r.ablated(), list(r.ablated_holdout_errors)) for r in singles]
    best_base, best_errors = min([(fit, errors) for fit, errors in bases if np.isfinite(rmse_mm(errors))],
                                 key=lambda pair: pair[0].train_rmse_mm)
    improved_by = None
    if best_base is not baseline:
        improved_by = "the plain refit" if best_base is refit.fit else "a candidate with its effect switched off"
        say(f"baseline: improved from {baseline.train_rmse_mm:.4f} to {best_base.train_rmse_mm:.4f} mm (training; "
            f"{improved_by})")
        baseline, base_errors = best_base, best_errors
        singles = [replace(evaluate(r.effects, r.fit, r.holdout_errors, base_errors, split), seconds=r.seconds,
                           ablated_train_rmse_mm=r.ablated_train_rmse_mm,
                           ablated_holdout_errors=r.ablated_holdout_errors) for r in singles]
        # A fit's minimum depends on where it starts: the best candidates again from the better base
        again = [r.effects[0] for r in ranked(singles)[:REFITS_FROM_BETTER_BASE]]
        say(f"candidates: {', '.join(again)} again from the better baseline")
        refits = {r.effects: r for r in run_tasks([task({i: start_values(i)}, baseline) for i in again], pool)}
        singles = [better_start(r, refits.get(r.effects)) for r in singles]
    singles = ranked(singles)
    base_rmse = rmse_mm(base_errors)
    timing["candidates"] = time.perf_counter() - clock - sum(timing.values())

    zeros = baseline.zero_offsets_mm
    tensions = [predict_tips_and_tension(baseline.params, baseline.terms(), np.asarray(zeros), r, res)[1]
                if r.tendon_force_n is None or not np.isfinite(r.tendon_force_n).all() else None for r in held]
    features = compute_features(held, zeros, tensions)
    chosen_features = features.subset(split.selection_mask)

    largest_tension = max((t for t in (r.max_summed_tension_n for r in train) if t is not None), default=None)
    hold_s = longest_hold_s(features, np.concatenate([r.t_s[r.valid] for r in held]))

    def rejections(result: CandidateResult, before: CandidateResult | None = None) -> list[str]:
        """Why the result is not a found effect (empty: it is). It must have predicted every held-out
        sample; be meaningful (selection half) against the baseline (`before`: the single it adds a
        second effect to) and against its own ablation, the same fit with the effect switched off (the
        effect, not the refit of the base parameters that came with it, removes the error); and be
        plausible: its parameters inside their physical range, its gain where its signature says, and
        no tip motion during static holds that the measured tip does not show. And there must be
        something to explain: the baseline's error on the selection half significant against the
        tracker noise (`significance.is_significant_residual`), else the verdict is `none`."""
        if result.failed:
            return ["its held-out prediction failed (the model diverged or was given up): never a verdict"]
        before_all = before.holdout_errors if before else base_errors
        before_errors = split.selected(before_all)
        before_rmse = rmse_mm(before_errors)
        within_noise = None if before else nothing_to_explain(before_rmse, noise)
        reasons = [f"{within_noise} on the selection half"] if within_noise else []
        if not is_meaningful(before_rmse, result.holdout_rmse_mm, noise):
            reasons.append(f"not significant: {before_rmse:.3f} -> {result.holdout_rmse_mm:.3f} mm on the selection "
                           "half removes no more than noise and fitting freedom explain")
        elif not before and result.ablated_holdout_errors and not is_meaningful(
                rmse_mm(split.selected(result.ablated_holdout_errors)), result.holdout_rmse_mm, noise):
            reasons.append(f"the refit, not the effect, removes the error: with the effect switched off the fit "
                           f"reaches {rmse_mm(split.selected(result.ablated_holdout_errors)):.3f} mm")
        added = result.effects[-1]
        reasons += range_reasons(added, result.fit.effects[added], train[0].flexible_length_mm,
                                 1.0 / res.fit_rate_hz, train[0].flexible_length_mm / res.n_elements,
                                 largest_tension, hold_s)
        reasons += signature_reasons(added, chosen_features, np.concatenate(before_errors),
                                     np.concatenate(split.selected(result.holdout_errors)), noise)[0]
        reasons += hold_drift_reasons(added, features, split.selection_mask, np.concatenate(before_all),
                                      np.concatenate(result.holdout_errors), noise)
        return reasons

    chosen: list[CandidateResult] = []
    pairs: list[CandidateResult] = []
    found_singles = [r for r in singles if not rejections(r)]
    eligible = simplest_sufficient(found_singles, noise)
    simpler_than = []   # the richer found effect that scored higher but gave way (simplest_effect)
    if eligible and eligible[0] is not found_singles[0]:
        richer, simpler = found_singles[0], eligible[0]
        simpler_than = [{"effect": richer.effects[0],
                         "reason": f"{richer.effects[0]} has {parameter_count(richer)} free parameters, "
                                   f"{simpler.effects[0]} {parameter_count(simpler)}, and {richer.effects[0]} removes "
                                   f"no more error than noise and fitting freedom explain beyond it "
                                   f"({simpler.holdout_rmse_mm:.3f} -> {richer.holdout_rmse_mm:.3f} mm on the "
                                   "selection half)"}]
        say(f"{eligible[0].effects[0]} leads: {simpler_than[0]['reason']}")
    if eligible and settings.pair_candidates == 0:
        chosen = [eligible[0]]
    elif eligible:
        best = eligible[0]
        # second effects: the next best singles that are found on their own
        others = [r.effects[0] for r in eligible[1:settings.pair_candidates + 1]]
        say(f"pairs: {best.effects[0]} alone (control) and with each of {', '.join(others)}" if others else
            f"pairs: no second effect is found on its own; refitting {best.effects[0]} alone (control)")
        continued, *pairs = run_tasks([task(dict(best.fit.effects), best.fit, CONTINUE)]
                                      + [task({**best.fit.effects, other: start_values(other)}, best.fit, PROBE)
                                         for other in others], pool)
        # the control got further: it is the single, if it still predicts and still is a found effect
        if continued.fit.train_rmse_mm < best.fit.train_rmse_mm and not rejections(continued):
            singles[singles.index(best)] = best = replace(continued, seconds=best.seconds + continued.seconds,
                                                          started_from=best.started_from,
                                                          train_rmse_mm_by_start=best.train_rmse_mm_by_start)
        chosen = [best]
        pairs = ranked(pairs)
        if pairs and not rejections(pairs[0], best):
            chosen.append(pairs[0])
    listed = {row["effect"] for row in simpler_than} | set(chosen[-1].effects if chosen else ())
    as_good = [{"effect": r.effects[0], "selection_rmse_mm": r.holdout_rmse_mm,
                "reason": f"{chosen[0].effects[0]} removes no more error than noise and fitting freedom explain "
                          f"beyond it ({r.holdout_rmse_mm:.3f} -> {chosen[0].holdout_rmse_mm:.3f} mm on the selection "
                          "half), so these logs cannot tell them apart"}
               for r in (as_good_as(chosen[0], eligible, noise) if chosen else []) if r.effects[0] not in listed]
    timing["pairs"] = time.perf_counter() - clock - sum(timing.values())

    say("where: residual by region and signatures")
    found = regions(features)
    base_stack = np.concatenate(base_errors)
    where = breakdown(found, base_stack)
    model_tips = [predict_tips(baseline.params, baseline.terms(), np.asarray(zeros), r, res) for r in held]
    signature = signatures(features, base_stack, held, model_tips, zeros, noise)
    final = chosen[-1] if chosen else None
    after_stack = np.concatenate(final.holdout_errors) if final else base_stack
    after_fit = final.fit if final else baseline
    after_tips = [predict_tips(after_fit.params, after_fit.terms(), np.asarray(after_fit.zero_offsets_mm), r, res)
                  for r in held] if final else model_tips
    after_signature = signatures(features, after_stack, held, after_tips, zeros, noise) if final else signature
    timing["where"] = time.perf_counter() - clock - sum(timing.values())

    base_report_rmse = rmse_mm(split.reported(base_errors))
    after_rmse = rmse_mm([after_stack])
    after_where = breakdown(found, after_stack)
    unexplained = not final and is_significant_residual(base_rmse, noise)
    drift = base_drift(prior, after_fit.params)
    named, after_report_rmse = list(final.effects) if final else [], final.report_rmse_mm if final else base_report_rmse
    floor = None if noise is None else float(np.sqrt(3) * noise)
    verdict = {
        "effect": chosen[0].effects[0] if chosen else UNEXPLAINED if unexplained else "none",
        "effects": named,
        "holdout_rmse_before_mm": base_report_rmse,
        "holdout_rmse_after_mm": after_report_rmse,
        "shrink": final.report_shrink if final else 0.0,
        "confidence": confidence(named, base_report_rmse, after_report_rmse, floor),
        "confidence_line": confidence_line(named, base_report_rmse, after_report_rmse, floor),
        "selection_shrink": final.shrink if final else 0.0,
        "shrink_estimate": split.as_dict(),
        "params": final.fit.effect_params() if final else {},
        "shrink_by_region": shrink_by_region(found, base_stack, after_stack) if final else [],
        "base_parameter_change": _base_change(baseline, final.fit) if final else [],
        "residual": describe(after_signature, after_where, after_rmse) + describe_drift(drift),
        "base_drift": drift,
        "residual_concentrated": [row["region"] for row in concentrated(after_where)],
        "model_form_rms_mm": model_form_rms_mm(after_rmse, noise),
        "simpler_than": simpler_than if final else [],
        "as_good": as_good,
        "rejected": [] if final else [{"effect": r.effects[0], "reasons": rejections(r)} for r in singles[:3]],
        "fit": after_fit.as_dict(),
    }
    timing["total"] = time.perf_counter() - clock
    result = {
        "format": FORMAT,
        "baseline": {"train_rmse_mm": baseline.train_rmse_mm, "holdout_rmse_mm": base_rmse,
                     "report_rmse_mm": base_report_rmse, "noise_mm": noise,
                     "noise_floor_mm": floor,
                     "residual_significant": is_significant_residual(base_rmse, noise),
                     "improved_by": improved_by, "fit": baseline.as_dict()},
        "constant_curvature": {**reference.as_dict(), "holdout_rmse_mm": rmse_mm(reference_errors),
                               "report_rmse_mm": rmse_mm(split.reported(reference_errors))},
        "holdout_by_recording": [
            {"recording": r.name, "rows_used_with_tip": len(cc), "constant_curvature_mm": rmse_mm([cc]),
             "baseline_mm": rmse_mm([base]), "verdict_mm": rmse_mm([after])}
            for r, cc, base, after in zip(held, reference_errors, base_errors,
                                         final.holdout_errors if final else base_errors)],
        "where": where,
        "concentrated": [row["region"] for row in concentrated(where)],
        "signatures": signature,
        "candidates": [{**r.as_dict(), "found": not (reasons := rejections(r)), "rejected": reasons,
                        "signature_concentration": _concentration(r, chosen_features, split, base_errors)}
                       for r in singles],
        "pairs": [r.as_dict() for r in pairs],
        "verdict": verdict,
        "coverage": coverage_lines(fit_rows, held, zeros),
        "settings": {**asdict(settings), "train": [r.name for r in train], "holdout": [r.name for r in holdout],
                     "geometry": {"tendon_offset_mm": baseline.params.tendon_offset_mm,
                                  "flexible_length_mm": train[0].flexible_length_mm}},
        "sampling": res.sampling(train, holdout),
        "timing_s": timing,
    }
    result, nulls = finite_tree(result)
    return {**result, "non_finite": nulls}


def better_start(first: CandidateResult, again: CandidateResult | None) -> CandidateResult:
    """The candidate fitted from the calibration (`first`) or again from the better baseline (`again`,
    None: not fitted again), whichever fits the training recordings better, with both training RMSEs.

    On a rod log (seed 86, case 8) a precurvature fitted from the calibration removed 0.09 of the
    selection half's error; from the base-only fit that had beaten the calibration it removed 0.22
    and was found, where the withheld truth was that precurvature.
    """
    if again is None:
        return first
    kept = again if again.fit.train_rmse_mm < first.fit.train_rmse_mm else first
    return replace(kept, started_from="better baseline" if kept is again else "calibration",
                   train_rmse_mm_by_start={"calibration": first.fit.train_rmse_mm,
                                           "better baseline": again.fit.train_rmse_mm})


def _concentration(result: CandidateResult, features: SampleFeatures, split: HoldoutSplit,
                   base_errors: Sequence[np.ndarray]) -> dict:
    """The candidate's gain concentration in its signature region (selection half), for the JSON."""
    value, region = (None, "") if result.failed else signature_concentration(
        result.effects[0], features, np.concatenate(split.selected(base_errors)),
        np.concatenate(split.selected(result.holdout_errors)))
    return {"region": region or None, "concentration": value}


def _holdout_errors(fit: ModelFit, held: Sequence[Recording], res: Resolution) -> list[np.ndarray]:
    errors = tip_errors(fit, held, res)
    if not all(np.isfinite(e).all() for e in errors):
        raise RecordingError("the calibrated model diverged on the held-out recordings; check that they come "
                             "from the same catheter as the training recordings")
    return errors


def _base_change(before: ModelFit, after: ModelFit) -> list[dict]:
    """How each base parameter moved when the effect was added (relative for stiffness and friction).

    baseline_std: the baseline fit's standard deviation, None where it has none (e.g. a baseline
    taken from a candidate's fit with its effect switched off).
    """
    std = dict(zip(before.names, before.std))
    after_values = base_values(after.params, after.zero_offsets_mm)
    rows = []
    for name, a in base_values(before.params, before.zero_offsets_mm).items():
        b = after_values[name]
        rows.append({"name": name, "baseline": a, "with_effect": b, "change": b - a,
                     "relative_change": (b - a) / a if a != 0 and not name.startswith("tendon_zero") else None,
                     "baseline_std": std[name] if np.isfinite(std.get(name, np.nan)) else None})
    return rows
