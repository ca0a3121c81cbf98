"""Blind validation of the gap diagnosis on data whose effect is withheld, per plant family.

Families: `dahl`, the default plant (the model's own equations at a finer resolution, so only
the parameters and the drawn effects differ from the model) and `rod`, an independently written
Kirchhoff-rod plant (`family = "rod"` in its plant TOML) whose structure differs from the model:
there the diagnosis has to cope with model-form error as well.

Per case: draw an effect (or none, or two; on the rod family also an effect that only the plant
has: out of catalog) at a magnitude drawn log-uniformly from the family's range table, down to
below the tracker noise (`crest.gap.effect_draws`), a plant whose base parameters and tendon
zeros differ from the prior catheter, and random tracker noise and dropout. The plant is written
as a plant description (`--plant-config`, kept in the case's `plant/` folder) and the training and
held-out logs are recorded on the virtual testbed through `crest excite`'s own path
(crest/experiment/excitation_run.py: simulated CiA 402 drives, the plant behind them, the
simulated tracker, the recorder), in simulated time. The diagnosis then runs on the two log
files alone (`diagnose_logs` sees paths, never the draw), and is scored against the draw.

Scores, per family (`score`): confusion matrix (true id -> verdict.effect); top-1 on single
effects (all, and above the detection limit: the effect moves the held-out tip by at least the
tracker noise floor and by at least DETECTION_RATIO of the baseline residual); the detection-limit
curve, top-1 per effect against the effect's size relative to the baseline residual
(effect RMS / held-out baseline RMSE); on clean cases the share with no catalog effect named
(`none` and `unexplained` both right); on out-of-catalog cases the share `unexplained` and the
number with a catalog effect named, and how many of those the verdict grades `confident`
(`model.gap.verdict_confidence`: the named effect at least halves the report half's error above
the noise floor; the same count on clean cases, and the confident right and wrong verdicts above
the detection limit); how often the true effect is the best-ranked candidate above the detection
limit (the verdict names a candidate or nothing, so this bounds the top-1 that any verdict rule
could reach on these fits); the misses above the detection limit by cause (`crest.gap.miss_causes`:
absorbed by the base model, the fitted true effect removing nothing significant, or the
diagnosis's own); the largest share of the error any candidate removed on
clean and on out-of-catalog cases (what catalog effects can take up where the catalog holds
nothing); pair accuracy (dahl); and the error of the published shrink
against an oracle shrink on the same report half of the held-out log
(`model.gap.holdout_split`), over the cases with an effect (clean cases are left out: their
predicted and oracle shrink are both about 0, which would flatter the mean).

Oracles: dahl, the true effects added to the model and calibrated with the base parameters on
the training log from the drawn values (`oracle_shrinks`; the exact drawn plant is reported
beside it). rod, whose effects are not the model's: the true catalog effect fitted as the
diagnosis fits a candidate, from the diagnosis' baseline on the training log with twice the
iterations, evaluated on the report half (it measures the selection bias and the fit, not what
the model form leaves). Effect size: dahl, the RMS distance between the true plant's held-out
tips with and without its effects (model runs); rod, the same from a second held-out recording
of the plant without its effects, corrected for the two logs' independent noise,
sqrt(max(d^2 - 2 f^2, 0)) with f^2 = 3 sigma^2.

Visible size (rod family, single effects): an effect the base model absorbs leaves nothing to
name, however far it moves the tip. The part it cannot absorb, `crest.gap.visible_effect` (the base
model calibrated in-sample on the held-out log and on the plain held-out log), relative to the
baseline residual, gives a second detection limit and curve beside the raw one; the issue's
target is scored on the raw one.
"""
from __future__ import annotations

import json
import math
import tempfile
import threading
import time
from collections.abc import Callable, Mapping
from concurrent.futures import Executor, ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from crest.backend import plant_description_refusal, plant_effect_ranges
from crest.config import TestbedConfig, load_testbed_config
from crest.driver import SafetyStop
from crest.experiment.excitation_run import ExcitationPlan, plan_excitation, record_excitation
from crest.gap.effect_draws import DAHL_EFFECT_RANGES, catalog_ids, draw_effect, out_of_catalog_ids
from crest.gap.isolated_call import CallTimedOut, call_isolated
from crest.gap.log_diagnosis import diagnose_logs
from crest.gap.log_recordings import load_recordings
from crest.gap.miss_causes import miss_causes
from crest.gap.synthetic_logs import Plant
from crest.gap.visible_effect import visible_effect_mm
from crest.session import SessionOptions, open_session
from model import CatheterParams
from model.effects import effect
from model.gap.calibration import ModelFit, calibrate, rmse_mm, tip_errors
from model.gap.candidates import EXPLORE, FitTask, run_task
from model.gap.diagnosis import UNEXPLAINED, DiagnosisSettings
from model.gap.holdout_split import split_holdout
from model.gap.simulation import catheter_for
from model.gap.starting_points import start_values
from model.gap.verdict_confidence import CONFIDENT, confidence

FAMILIES = ("dahl", "rod")
CLEAN_FRACTION = 0.2
PAIR_FRACTION = 0.15              # dahl
OUT_OF_CATALOG_FRACTION = 0.2     # rod: effects only the plant has
MAX_REDRAWS = 5
DETECTION_RATIO = 0.5             # effect RMS / baseline residual above which an effect counts as detectable
RATIO_EDGES = (0.0, 0.1, 0.2, 0.35, 0.5, 0.7, 1.0, math.inf)   # bins of the detection-limit curve
TARGETS = {"top1_single_above_detection": 0.9, "no_catalog_effect_clean": 0.8, "unexplained_out_of_catalog": 0.8,
           "shrink_error_pp": 10.0}
NO_RESULT = "no result"
ALL_EFFECTS = "all effects"       # the detection-limit curve pooled over every effect
# A plant whose solver fails loses the tracker's tip (the virtual tracker reports the tool missing),
# reports absurd tensions (the testbed's safety stop ends the run) or never returns (the recording
# exceeds its time limit). Each way the case is redrawn.
MIN_TIP_FRACTION_BEYOND_DROPOUT = 0.9
RECORD_TIMEOUT_S = 900.0      # recording both logs normally takes 1-2 min
DIAGNOSIS_TIMEOUT_S = 900.0   # a diagnosis normally takes 15-40 s
# A recording keeps one core busy, a diagnosis two: two cases at once keep a 2-core machine busy.
# The verdicts do not depend on it (the diagnosis limits solver iterations, not time).
PARALLEL_CASES = 2


class PlantFailure(RuntimeError):
    """The drawn plant's solver failed or crawled on the excitation: no usable log was recorded."""


@dataclass(frozen=True)
class RodDraw:
    """A rod plant (`family = "rod"`): its base tables {table: {key: value}} and effects {id: {param: value}}."""

    tables: Mapping[str, Mapping[str, object]]
    effects: Mapping[str, Mapping[str, float]] = field(default_factory=dict)


@dataclass(frozen=True)
class BlindCase:
    """The hidden truth of one case: the plant behind the drives and the tracker's imperfections."""

    index: int
    kind: str                     # "single", "none", "pair" or "out_of_catalog"
    plant: Plant | RodDraw
    tracker_noise_mm: float       # per axis std
    tracker_dropout: float        # fraction of tracker frames with the tool missing
    seed: int
    redraws: int = 0
    family: str = "dahl"

    @property
    def effects(self) -> tuple[str, ...]:
        return tuple(self.plant.effects)


def effect_ranges(family: str) -> dict[str, dict]:
    """The family's range table (`crest.gap.effect_draws`)."""
    if family == "dahl":
        return DAHL_EFFECT_RANGES
    if family == "rod":
        return plant_effect_ranges("rod")
    raise ValueError(f"unknown plant family {family!r}; families: {', '.join(FAMILIES)} (or both)")


def random_plant(prior: CatheterParams, effect_ids: tuple[str, ...], rng: np.random.Generator) -> Plant:
    """Base parameters off the prior (EI x/÷1.4, EA x/÷2, sigma x/÷2, mu 0.12-0.3, Fsc 0.5-1.6 x), tendon
    zeros of a few micrometres (about 1 N of pretension), and the effects drawn from DAHL_EFFECT_RANGES."""
    params = prior.replace(
        bending_stiffness_nmm2=prior.bending_stiffness_nmm2 * math.exp(rng.uniform(-0.35, 0.35)),
        axial_stiffness_n=prior.axial_stiffness_n * math.exp(rng.uniform(-0.7, 0.7)),
        sigma_n_per_mm2=prior.sigma_n_per_mm2 * math.exp(rng.uniform(-0.7, 0.7)),
        mu=rng.uniform(0.12, 0.3), fsc_n_per_mm=prior.fsc_n_per_mm * rng.uniform(0.5, 1.6))
    zeros = tuple(float(v) for v in rng.normal(0.0, 0.002, 4))
    effects = {e: effect(e).values_from(draw_effect(DAHL_EFFECT_RANGES, e, rng)) for e in effect_ids}
    return Plant(params, effects, zeros)


def random_rod_plant(effect_ids: tuple[str, ...], rng: np.random.Generator,
                     ranges: Mapping[str, dict]) -> RodDraw:
    """A rod plant around its own defaults (configs/rod_plant.toml): Young's modulus x/÷1.25, mu 0.15-0.3,
    constant friction 0.6-1.5 x, tendon zeros of a few micrometres, the effects drawn from `ranges`."""
    tables = {"shaft": {"youngs_modulus_mpa": 13.5 * math.exp(rng.uniform(-0.22, 0.22))},
              "tendons": {"zero_offsets_mm": [float(v) for v in rng.normal(0.0, 0.002, 4)]},
              "friction": {"mu": float(rng.uniform(0.15, 0.3)), "constant_n_per_mm": 0.006 * rng.uniform(0.6, 1.5)}}
    return RodDraw(tables, {e: draw_effect(ranges, e, rng) for e in effect_ids})


def draw_cases(count: int, seed: int, prior: CatheterParams, family: str = "dahl") -> list[BlindCase]:
    """`count` cases of the family: about 20 % clean, and on dahl 15 % pairs, on rod 20 % out of catalog,
    the rest single effects cycling through the catalog; tracker noise 0.05-0.2 mm per axis and 0-2 %
    dropout. The rod family's draw is seeded apart from the dahl family's."""
    ranges = effect_ranges(family)
    rng = np.random.default_rng(seed if family == "dahl" else [seed, FAMILIES.index(family)])
    n_clean = round(CLEAN_FRACTION * count)
    n_pair = round(PAIR_FRACTION * count) if family == "dahl" else 0
    n_outside = round(OUT_OF_CATALOG_FRACTION * count) if family == "rod" else 0
    ids = catalog_ids(ranges)
    order = [str(e) for e in rng.permutation(ids)]
    outside = out_of_catalog_ids(ranges)
    kinds = (["none"] * n_clean + ["pair"] * n_pair + ["out_of_catalog"] * n_outside
             + ["single"] * (count - n_clean - n_pair - n_outside))
    kinds = [kinds[i] for i in rng.permutation(count)]
    cases = []
    singles = outsiders = 0
    for index, kind in enumerate(kinds):
        if kind == "single":
            chosen = (order[singles % len(order)],)
            singles += 1
        elif kind == "out_of_catalog":
            chosen = (outside[outsiders % len(outside)],)
            outsiders += 1
        elif kind == "pair":
            chosen = tuple(str(e) for e in rng.choice(ids, size=2, replace=False))
        else:
            chosen = ()
        case_seed = int(rng.integers(2 ** 31))
        case_rng = np.random.default_rng(case_seed)
        noise_mm, dropout = case_rng.uniform(0.05, 0.2), case_rng.uniform(0.0, 0.02)
        plant = random_plant(prior, chosen, case_rng) if family == "dahl" else random_rod_plant(chosen, case_rng,
                                                                                                   ranges)
        cases.append(BlindCase(index, kind, plant, noise_mm, dropout, case_seed, family=family))
    return cases


def _toml_value(value) -> str:
    return "[" + ", ".join(repr(float(v)) for v in value) + "]" if isinstance(value, (list, tuple)) \
        else repr(float(value))


def write_plant_config(case: BlindCase, folder: Path, with_effects: bool = True) -> Path:
    """The case's plant as a plant description (configs/virtual_plant.toml's format, or
    configs/rod_plant.toml's for the rod family) in `folder`; returns its path. with_effects False:
    the same plant without its effects (the rod family's reference for the effect size)."""
    folder.mkdir(parents=True, exist_ok=True)
    tracker = ["[tracker]", f"noise_mm = {case.tracker_noise_mm!r}", f"dropout = {case.tracker_dropout!r}",
               f"seed = {case.seed}", ""]
    effects = []
    for effect_id, values in (case.plant.effects.items() if with_effects else ()):
        named = values.items() if isinstance(values, Mapping) else zip(effect(effect_id).param_names, values)
        effects.append(f"{effect_id} = {{ {', '.join(f'{name} = {float(v)!r}' for name, v in named)} }}")
    if case.family == "rod":
        lines = ['family = "rod"', ""]
        for table, values in case.plant.tables.items():
            lines += [f"[{table}]", *(f"{key} = {_toml_value(v)}" for key, v in values.items()), ""]
        lines += ["[effects]", *effects, "", *tracker]
    else:
        (folder / "catheter.toml").write_text(case.plant.params.to_toml())
        lines = ['catheter = "catheter.toml"', f"n_elements = {case.plant.n_elements}",
                 f"tendon_zero_offsets_mm = [{', '.join(repr(float(v)) for v in case.plant.zero_offsets_mm)}]", "",
                 "[effects]", *effects, "", *tracker]
    path = folder / ("rod_plant.toml" if case.family == "rod" else "virtual_plant.toml")
    path.write_text("\n".join(lines))
    return path


def _redrawn(case: BlindCase, redraw: int, prior: CatheterParams) -> BlindCase:
    """The case with a new plant (same effects, same kind), drawn from a seed of its own."""
    rng = np.random.default_rng(case.seed + 7919 * redraw)
    plant = random_plant(prior, case.effects, rng) if case.family == "dahl" else \
        random_rod_plant(case.effects, rng, effect_ranges(case.family))
    return BlindCase(case.index, case.kind, plant, case.tracker_noise_mm, case.tracker_dropout, case.seed, redraw,
                     case.family)


def record_case(case: BlindCase, folder: Path, config: TestbedConfig, plan: ExcitationPlan,
                prior: CatheterParams, cancel: threading.Event | None = None
                ) -> tuple[BlindCase, Path, Path, Path | None]:
    """Training and held-out logs of the case's plant on the virtual testbed, as `crest excite` records
    them (in a process of its own, see `call_isolated`; ended once `cancel` is set), and on the rod family
    with an effect a second held-out log of the plant without it (None otherwise); a plant whose solver
    fails, or that its own description refuses (a drawn lumen drift that puts the lumens outside the
    shaft), is redrawn."""
    refusals = []
    for redraw in range(MAX_REDRAWS + 1):
        if redraw:
            case = _redrawn(case, redraw, prior)
        plant_toml = write_plant_config(case, folder / f"plant_{redraw}")
        refused = plant_description_refusal(plant_toml)
        if refused is not None:
            refusals.append(refused)
            continue
        options = SessionOptions(config=config, plant_config=plant_toml, realtime=False, in_process=True)
        try:
            results = call_isolated(_record, options, plan, folder / f"logs_{redraw}", prior,
                                    timeout_s=RECORD_TIMEOUT_S, cancel=cancel)
        except (PlantFailure, CallTimedOut):
            continue
        if not all(r.tip_samples >= MIN_TIP_FRACTION_BEYOND_DROPOUT * (1.0 - case.tracker_dropout) * r.tracker_frames
                   for r in results.values()):
            continue
        reference = None
        if case.family == "rod" and case.effects:
            plain = SessionOptions(config=config, realtime=False, in_process=True,
                                   plant_config=write_plant_config(case, folder / f"plant_{redraw}_plain", False))
            held_only = ExcitationPlan(plan.conditioning, {"holdout": plan.logs["holdout"]})
            try:
                reference = call_isolated(_record, plain, held_only, folder / f"logs_{redraw}_plain", prior,
                                          timeout_s=RECORD_TIMEOUT_S, cancel=cancel)["holdout"].log_path
            except (PlantFailure, CallTimedOut):
                continue
        return case, results["train"].log_path, results["holdout"].log_path, reference
    raise PlantFailure(f"blind case {case.index}: the plant failed in {MAX_REDRAWS + 1} draws"
                       + (f" ({len(refusals)} refused by its description, last: {refusals[-1]})" if refusals else ""))


def _record(options: SessionOptions, plan: ExcitationPlan, folder: Path, prior: CatheterParams) -> dict:
    try:
        with open_session(options) as session:
            return record_excitation(session, plan, folder, prior)
    except SafetyStop as stop:      # a diverged plant reported absurd tensions
        raise PlantFailure(str(stop)) from None


def oracle_shrinks(case: BlindCase, train: Path, holdout: Path, prior: CatheterParams, baseline_rmse_mm: float,
                   settings: DiagnosisSettings) -> tuple[float, float, float]:
    """Dahl family: the held-out shrink 1 - RMSE / baseline RMSE on the report half when the true effects
    are added, two ways, and the size of the effects:

    fitted (the oracle the prediction is scored against): the true effects added to the model and
    calibrated with the base parameters on the training log, from the true plant's values, as the
    diagnosis fits a candidate (where that fit ends worse on the training log than the true plant
    itself, a local minimum, the true plant is the oracle); exact: the true plant simulated at the
    diagnosis' resolution (it also carries the difference between that resolution and the
    plant's); effect size: the RMS distance on the whole held-out log between the true plant's tip
    with and without its effects.
    """
    res = settings.resolution
    held = res.prepare(load_recordings([holdout]))
    training = load_recordings([train])
    truth = ModelFit(catheter_for(case.plant.params, [*held, *training]), case.plant.zero_offsets_mm,
                     dict(case.plant.effects))
    fitted = calibrate(training, case.plant.params, prior=prior, zero_offsets_mm=case.plant.zero_offsets_mm,
                       effects=dict(case.plant.effects), resolution=res, max_iterations=settings.candidate_iterations)
    if rmse_mm(tip_errors(truth, res.prepare_training(training), res)) < fitted.train_rmse_mm:
        fitted = truth
    truth_errors = tip_errors(truth, held, res)
    without = tip_errors(ModelFit(truth.params, truth.zero_offsets_mm, {}), held, res)
    effect_rms_mm = rmse_mm([a - b for a, b in zip(truth_errors, without)])
    split = split_holdout([len(e) for e in truth_errors])
    fitted_shrink, exact_shrink = (1.0 - rmse_mm(split.reported(errors)) / baseline_rmse_mm
                                   for errors in (tip_errors(fitted, held, res), truth_errors))
    return fitted_shrink, exact_shrink, effect_rms_mm


def rod_oracle_shrink(effect_id: str, result: dict, train: Path, holdout: Path, prior: CatheterParams,
                      settings: DiagnosisSettings) -> float:
    """Rod family: the true catalog effect fitted as the diagnosis fits a candidate, from its baseline with
    twice the iterations, scored on the report half (see module doc)."""
    res = settings.resolution
    held = res.prepare(load_recordings([holdout]))
    baseline = ModelFit.from_dict(result["baseline"]["fit"])
    base_errors = tip_errors(baseline, held, res)
    split = split_holdout([len(e) for e in base_errors])
    fitted = run_task(FitTask({effect_id: start_values(effect_id)}, baseline, prior, tuple(load_recordings([train])),
                              tuple(held), tuple(base_errors), split, res, 2 * settings.candidate_iterations,
                              EXPLORE))
    return fitted.report_shrink


def rod_effect_rms_mm(holdout: Path, reference: Path, noise_mm: float) -> float:
    """The effect's size on the held-out log: RMS of the tip difference with and without it over the
    rows both logs measured, less the two logs' independent noise (see module doc)."""
    with_effect, without = (load_recordings([path])[0] for path in (holdout, reference))
    n = min(len(with_effect), len(without))
    d = with_effect.tip_mm[:n] - without.tip_mm[:n]
    d = d[np.all(np.isfinite(d), axis=1)]
    return float(math.sqrt(max(float(np.mean(np.sum(d ** 2, axis=1))) - 2 * 3 * noise_mm ** 2, 0.0)))


def run_case(case: BlindCase, folder: Path, config: TestbedConfig, plan: ExcitationPlan,
             prior: CatheterParams, settings: DiagnosisSettings, executor: Executor | None = None,
             cancel: threading.Event | None = None) -> dict:
    """Record, diagnose blind, and compare with the truth. A plant that keeps failing is skipped (reported).

    executor None: the diagnosis runs in a process of its own (`call_isolated`, with its own worker
    processes and a time limit). Else its fits and the oracle's fit run on the executor (a Dask
    cluster, `crest.gap.fit_executor`) and the rest of it here; the numbers are the same.
    cancel: once set, the recording or diagnosis running in a process of its own is ended (CallCancelled).
    """
    start = time.perf_counter()
    head = {"case": case.index, "family": case.family, "kind": case.kind, "truth": list(case.effects)}
    try:
        case, train, holdout, reference = record_case(case, folder, config, plan, prior, cancel)
    except PlantFailure as error:
        return {**head, "skipped": str(error)}
    recorded = time.perf_counter()
    try:
        result = call_isolated(diagnose_logs, [train], [holdout], settings=settings, timeout_s=DIAGNOSIS_TIMEOUT_S,
                               cancel=cancel) if executor is None else diagnose_logs([train], [holdout], settings=settings, executor=executor)
    except CallTimedOut as error:
        return {**head, "redraws": case.redraws, "record_seconds": recorded - start, "no_result": str(error)}
    seconds = time.perf_counter() - recorded
    verdict = result["verdict"]
    floor = result["baseline"]["noise_floor_mm"]
    row = {**head, "truth_params": {k: (dict(v) if isinstance(v, Mapping) else list(v))
                                    for k, v in case.plant.effects.items()},
           "noise_mm": case.tracker_noise_mm, "dropout": case.tracker_dropout, "redraws": case.redraws,
           "predicted": verdict["effect"], "predicted_effects": verdict["effects"],
           "holdout_rmse_before_mm": verdict["holdout_rmse_before_mm"],
           "holdout_rmse_after_mm": verdict["holdout_rmse_after_mm"], "noise_floor_mm": floor,
           "baseline_holdout_rmse_mm": result["baseline"]["holdout_rmse_mm"],
           "model_form_rms_mm": verdict["model_form_rms_mm"], "predicted_shrink": verdict["shrink"],
           "predicted_confidence": verdict["confidence"],
           "as_good": [alternative["effect"] for alternative in verdict["as_good"]],
           "top_candidates": [c["effect"] for c in result["candidates"][:3]],
           "candidates": [candidate_summary(c) for c in result["candidates"]],
           "record_seconds": recorded - start, "seconds": seconds, "timing_s": result["timing_s"],
           "slowest_candidate": max(result["candidates"], key=lambda c: c["seconds"])["effect"]}
    if case.family == "dahl" and case.effects:
        oracle_args = (case, train, holdout, prior, verdict["holdout_rmse_before_mm"], settings)
        oracle, exact, effect_rms_mm = oracle_shrinks(*oracle_args) if executor is None else \
            executor.submit(oracle_shrinks, *oracle_args).result()
        row.update(oracle_shrink=oracle, exact_truth_shrink=exact)
    elif case.family == "rod" and case.effects:
        effect_rms_mm = rod_effect_rms_mm(holdout, reference, case.tracker_noise_mm)
        if case.kind == "single":
            oracle_args = (case.effects[0], result, train, holdout, prior, settings)
            row["oracle_shrink"] = rod_oracle_shrink(*oracle_args) if executor is None else \
                executor.submit(rod_oracle_shrink, *oracle_args).result()
            visible = visible_effect_mm(*load_recordings([holdout]), *load_recordings([reference]), prior, settings,
                                        executor)
            visible_relative = _relative(visible, row)
            row.update(visible_effect_mm=visible, visible_relative_size=visible_relative,
                       above_visible_limit=_above_limit(visible, visible_relative, case.tracker_noise_mm))
    else:
        effect_rms_mm = 0.0
    relative = _relative(effect_rms_mm, row)
    row.update(effect_rms_mm=effect_rms_mm, relative_size=relative,
               above_noise=effect_rms_mm >= math.sqrt(3.0) * case.tracker_noise_mm,
               above_detection_limit=_above_limit(effect_rms_mm, relative, case.tracker_noise_mm))
    if "oracle_shrink" in row and math.isfinite(row["oracle_shrink"]):
        row["shrink_error_pp"] = 100.0 * abs(verdict["shrink"] - row["oracle_shrink"])
    return row


def _relative(size_mm: float, row: dict) -> float:
    """An effect's size relative to the case's baseline residual (held-out RMSE)."""
    return size_mm / row["baseline_holdout_rmse_mm"] if row["baseline_holdout_rmse_mm"] > 0 else 0.0


def _above_limit(size_mm: float, relative: float, noise_mm: float) -> bool:
    """The detection limit: above the tracker noise floor (sqrt(3) sigma) and at least DETECTION_RATIO of
    the baseline residual."""
    return size_mm >= math.sqrt(3.0) * noise_mm and relative >= DETECTION_RATIO


def candidate_summary(candidate: dict) -> dict:
    """What a case's row keeps of each single candidate of its diagnosis, so that a miss can be
    studied from the benchmark's JSON: its shrink on the selection half, whether it was found,
    why not, and its gain's concentration in its signature region."""
    return {"effect": candidate["effect"], "selection_shrink": candidate["selection_shrink"],
            "found": candidate["found"], "rejected": candidate["rejected"],
            "signature_concentration": candidate["signature_concentration"]["concentration"],
            "params": candidate["params"]}


def detection_curve(rows: list[dict], size: str = "relative_size") -> dict[str, list[dict]]:
    """Top-1 per effect in bins of the effect's size relative to the baseline residual (RATIO_EDGES):
    its raw size ("relative_size") or its visible part ("visible_relative_size"); and under ALL_EFFECTS
    the same pooled over every effect, which shows whether any size limit reaches the top-1 target."""
    curve = {effect_id: _top1_bins([r for r in rows if r["truth"][0] == effect_id], size)
             for effect_id in sorted({r["truth"][0] for r in rows})}
    if curve:
        curve[ALL_EFFECTS] = _top1_bins(rows, size)
    return curve


def _top1_bins(rows: list[dict], size: str) -> list[dict]:
    """The share of `rows` whose verdict names their true effect, per bin of `size` (RATIO_EDGES)."""
    bins = []
    for low, high in zip(RATIO_EDGES[:-1], RATIO_EDGES[1:]):
        inside = [r for r in rows if size in r and low <= r[size] < high]
        if inside:
            bins.append({"ratio_low": low, "ratio_high": high if math.isfinite(high) else None,
                         "cases": len(inside),
                         "top1": float(np.mean([r["predicted"] == r["truth"][0] for r in inside]))})
    return bins


def score(all_rows: list[dict]) -> dict:
    """The scores of one family's cases (see module doc). Skipped cases (no plant could be recorded) are
    counted, not scored; a case whose diagnosis gave no result counts as wrong (verdict NO_RESULT)
    and has no shrink error."""
    rows = [r if "no_result" not in r else {**r, "predicted": NO_RESULT, "predicted_effects": []}
            for r in all_rows if "skipped" not in r]
    truths = sorted({r["truth"][0] for r in rows if r["kind"] in ("single", "out_of_catalog")})
    labels = truths + ["none", UNEXPLAINED, NO_RESULT]
    for r in rows:
        if r["predicted"] not in labels:
            labels.insert(len(truths), r["predicted"])
    confusion = {t: {p: 0 for p in labels} for t in truths + ["none"]}
    for row in rows:
        if row["kind"] in ("single", "none", "out_of_catalog"):
            confusion[row["truth"][0] if row["truth"] else "none"][row["predicted"]] += 1
    singles = [r for r in rows if r["kind"] == "single"]
    audible = [r for r in singles if r.get("above_noise", True)]     # a case without a result counts
    detectable = [r for r in singles if r.get("above_detection_limit", True)]
    visible = [r for r in singles if r.get("above_visible_limit", False)]
    ranked = [r for r in detectable if r.get("candidates")]     # results before 2026-11-24 kept no candidates
    clean = [r for r in rows if r["kind"] == "none"]
    outside = [r for r in rows if r["kind"] == "out_of_catalog"]
    pairs = [r for r in rows if r["kind"] == "pair"]
    errors = [r["shrink_error_pp"] for r in rows if "shrink_error_pp" in r and r["kind"] in ("single", "pair")]

    def fraction(hits: list[bool]) -> float | None:
        return float(np.mean(hits)) if hits else None

    return {
        "cases": len(all_rows),
        "top1_single": fraction([r["predicted"] == r["truth"][0] for r in singles]),
        "top1_single_above_noise": fraction([r["predicted"] == r["truth"][0] for r in audible]),
        "top1_single_above_detection": fraction([r["predicted"] == r["truth"][0] for r in detectable]),
        "detection_curve": detection_curve(singles),
        "top1_single_above_visible_limit": fraction([r["predicted"] == r["truth"][0] for r in visible]),
        "truth_ranked_first_above_detection": fraction([r["candidates"][0]["effect"] == r["truth"][0]
                                                        for r in ranked]),
        "misses_above_detection": miss_causes([r for r in detectable if r["predicted"] != r["truth"][0]]),
        "largest_candidate_shrink_clean": _largest_shrink(clean),
        "largest_candidate_shrink_out_of_catalog": _largest_shrink(outside),
        "visible_detection_curve": detection_curve(singles, "visible_relative_size"),
        "none_clean": fraction([r["predicted"] == "none" for r in clean]),
        "no_catalog_effect_clean": fraction([r["predicted"] in ("none", UNEXPLAINED) for r in clean]),
        "unexplained_out_of_catalog": fraction([r["predicted"] == UNEXPLAINED for r in outside]),
        "catalog_effect_out_of_catalog": sum(r["predicted"] not in ("none", UNEXPLAINED, NO_RESULT)
                                             for r in outside),
        "confident_catalog_effect_out_of_catalog": sum(_graded(r) == CONFIDENT for r in outside),
        "confident_catalog_effect_clean": sum(_graded(r) == CONFIDENT for r in clean),
        "confident_single_above_detection": {
            "right": sum(_graded(r) == CONFIDENT and r["predicted"] == r["truth"][0] for r in detectable),
            "wrong": sum(_graded(r) == CONFIDENT and r["predicted"] != r["truth"][0] for r in detectable)},
        "pair_exact": fraction([sorted(r["predicted_effects"]) == sorted(r["truth"]) for r in pairs]),
        "pair_any_found": fraction([bool(set(r["predicted_effects"]) & set(r["truth"])) for r in pairs]),
        "shrink_error_pp": {"mean": float(np.mean(errors)), "median": float(np.median(errors)),
                            "max": float(np.max(errors)), "cases": len(errors),
                            "within_10pp": float(np.mean([e <= 10.0 for e in errors]))} if errors else None,
        "confusion": confusion,
        "counts": {"single": len(singles), "single_below_noise": len(singles) - len(audible),
                   "single_above_detection": len(detectable), "single_above_visible_limit": len(visible),
                   "single_above_detection_with_candidates": len(ranked),
                   "single_with_visible_size": sum("visible_relative_size" in r for r in singles),
                   "none": len(clean), "pair": len(pairs),
                   "out_of_catalog": len(outside),
                   "skipped": len(all_rows) - len(rows), "no_result": sum("no_result" in r for r in rows)},
        "targets": TARGETS,
    }


def _graded(row: dict) -> str | None:
    """The verdict's confidence grade (`model.gap.verdict_confidence`); results stored before the grade
    existed (2026-12-06) get it from their stored report-half errors and noise floor, by the same rule."""
    if "predicted_confidence" in row:
        return row["predicted_confidence"]
    if not row["predicted_effects"]:
        return None
    return confidence(row["predicted_effects"], row["holdout_rmse_before_mm"], row["holdout_rmse_after_mm"],
                      row["noise_floor_mm"])


def _largest_shrink(rows: list[dict]) -> float | None:
    """The largest selection-half shrink of any candidate on these cases (None without candidates kept):
    how much catalog effects can take up where the catalog holds nothing (clean, out-of-catalog cases)."""
    shrinks = [c["selection_shrink"] for r in rows for c in r.get("candidates", [])
               if c.get("selection_shrink") is not None]
    return max(shrinks) if shrinks else None


def run_blind_benchmark(cases: int = 40, seed: int = 0, *, family: str = "dahl", short: bool = False,
                        settings: DiagnosisSettings = DiagnosisSettings(), work_dir: Path | str | None = None,
                        parallel_cases: int = PARALLEL_CASES, progress: Callable[[str], None] | None = None,
                        executor: Executor | None = None) -> dict:
    """Draw, record, diagnose and score `cases` blind cases per family ("dahl", "rod" or "both");
    returns {"score": {family: score}, "cases", "settings"}.

    work_dir keeps each case's plant description and logs (default: a temporary folder).
    parallel_cases: cases run at once (each records and diagnoses in processes of its own).
    executor: where the cases' fits run (see `run_case`); the scores do not depend on it.
    """
    families = list(FAMILIES) if family == "both" else [family]
    for name in families:
        effect_ranges(name)      # an unknown family fails here, before anything is recorded
    say = progress or (lambda message: None)
    prior = CatheterParams.from_toml()
    config = load_testbed_config()
    plan = plan_excitation(config, prior, short=short)
    rows = []
    drawn = [case for name in families for case in draw_cases(cases, seed, prior, name)]
    clock = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="crest-blind-") as scratch:
        root = Path(work_dir) if work_dir else Path(scratch)

        def run(case: BlindCase) -> dict:
            return run_case(case, root / f"{case.family}_case_{case.index:03d}", config, plan, prior, settings,
                            executor, cancel)

        cancel = threading.Event()

        pool = ThreadPoolExecutor(parallel_cases)
        try:
            for row in pool.map(run, drawn):
                rows.append(row)
                elapsed = time.perf_counter() - clock
                eta = elapsed / len(rows) * (len(drawn) - len(rows))
                head = (f"blind case {len(rows)}/{len(drawn)} ({row['family']} {row['case'] + 1}, {elapsed / 60:.0f} "
                        f"min, about {eta / 60:.0f} min left)")
                (root / "cases.json").write_text(json.dumps(rows, indent=1, default=str))   # kept should the run stop
                if "skipped" in row or "no_result" in row:
                    say(f"{head}: truth {'+'.join(row['truth']) or 'none'}, {row.get('skipped') or row['no_result']}")
                    continue
                oracle = f" (oracle {row['oracle_shrink']:.2f})" if "oracle_shrink" in row else ""
                say(f"{head}: truth {'+'.join(row['truth']) or 'none'}, verdict "
                    f"{'+'.join(row['predicted_effects']) or row['predicted']}, shrink {row['predicted_shrink']:.2f}"
                    f"{oracle}, recorded in {row['record_seconds']:.0f} s, diagnosed in {row['seconds']:.0f} s")
        finally:
            # On Ctrl-C no further case starts, and the running ones' recordings and local diagnoses are
            # ended; their fits on an executor end when the caller, once this returns, cancels them.
            cancel.set()
            pool.shutdown(wait=executor is None, cancel_futures=True)
    total = time.perf_counter() - clock
    return {"score": {name: score([r for r in rows if r["family"] == name]) for name in families}, "cases": rows,
            "settings": {"cases": cases, "seed": seed, "families": families,
                         "excitation": "short" if short else "standard",
                         "path": "virtual testbed, crest excite", "seconds": total,
                         "seconds_per_case": total / max(1, len(drawn))}}
