"""Blind validation of the gap diagnosis on data whose effect is withheld.

Per case: draw an effect (or none, or two) with random parameters, a plant whose base
parameters and tendon zeros differ from the prior catheter, and random tracker noise and
dropout. The plant is written as a virtual-plant description (`--plant-config`, kept in the
case's `plant/` folder) and the training and held-out logs are recorded on the virtual testbed
through `crest excite`'s own path (crest/experiment/excitation_run.py: simulated CiA 402
drives, the plant behind them, the simulated tracker, the recorder), in simulated time. The
diagnosis then runs on the two log files alone (`diagnose_logs` sees paths, never the draw),
and is scored against the draw.

Scores: confusion matrix (true id -> verdict.effect, single and clean cases), top-1 accuracy on
single effects (all of them, and those whose effect moves the held-out tip by at least the
tracker noise, 3-D RMS: below it no method can be expected to see it), `none` accuracy on clean
cases, pair accuracy (verdict.effects equals the true pair; and at least one found), and the
error of the predicted shrink against the oracle shrink 1 - RMSE(true effects added) /
RMSE(baseline) on the held-out log, where the true effects are added to the model and calibrated
with it on the training log, starting from the drawn values (`oracle_shrinks`; the shrink of the
exact drawn plant is reported beside it).
"""
from __future__ import annotations

import json
import math
import tempfile
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from crest.config import TestbedConfig, load_testbed_config
from crest.driver import SafetyStop
from crest.experiment.excitation_run import ExcitationPlan, plan_excitation, record_excitation
from crest.gap.isolated_call import CallTimedOut, call_isolated
from crest.gap.log_diagnosis import diagnose_logs
from crest.gap.log_recordings import load_recordings
from crest.gap.synthetic_logs import Plant
from crest.session import SessionOptions, open_session
from model import CatheterParams
from model.effects import EFFECTS, effect
from model.gap.calibration import ModelFit, calibrate, rmse_mm, tip_errors
from model.gap.diagnosis import DiagnosisSettings
from model.gap.simulation import catheter_for

CLEAN_FRACTION = 0.2
PAIR_FRACTION = 0.15
MAX_REDRAWS = 5
TARGETS = {"top1_single": 0.9, "none_clean": 0.8, "shrink_error_pp": 10.0}
NO_RESULT = "no result"
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
class BlindCase:
    """The hidden truth of one case: the plant behind the drives and the tracker's imperfections."""

    index: int
    kind: str                     # "single", "none" or "pair"
    plant: Plant
    tracker_noise_mm: float       # per axis std
    tracker_dropout: float        # fraction of tracker frames with the tool missing
    seed: int
    redraws: int = 0

    @property
    def effects(self) -> tuple[str, ...]:
        return tuple(self.plant.effects)


def random_effect_values(effect_id: str, rng: np.random.Generator) -> tuple[float, ...]:
    """A clearly present magnitude (0.6-1.5 x typical) in a random direction where the effect has one."""
    scale = rng.uniform(0.6, 1.5)
    typical = np.asarray(effect(effect_id).typical, dtype=float)
    if effect_id == "lumen_compression":
        return (scale * typical[0], rng.uniform(10.0, 40.0))
    if effect_id == "gravity":
        angle = rng.uniform(0, 2 * math.pi)
        g = 9.81 * rng.uniform(1.0, 2.0)     # 1 g sags the prior catheter 0.3 mm at 80 mm, 2 g 1 mm
        return (g * math.cos(angle), g * math.sin(angle), 9.81 * rng.uniform(-0.3, 0.3))
    if effect_id in ("tracker_offset", "precurvature"):
        direction = rng.normal(size=len(typical))
        return tuple(float(v) for v in scale * np.linalg.norm(typical) * direction / np.linalg.norm(direction))
    if effect_id == "torsion":
        return (float(rng.choice([-1.0, 1.0]) * scale * typical[0]),)
    return tuple(float(v) for v in scale * typical)


def random_plant(prior: CatheterParams, effect_ids: tuple[str, ...], rng: np.random.Generator) -> Plant:
    """Base parameters off the prior (EI x/÷1.4, EA x/÷2, sigma x/÷2, mu 0.12-0.3, Fsc 0.5-1.6 x), tendon
    zeros of a few micrometres (about 1 N of pretension), and the effects at random magnitudes."""
    params = prior.replace(
        bending_stiffness_nmm2=prior.bending_stiffness_nmm2 * math.exp(rng.uniform(-0.35, 0.35)),
        axial_stiffness_n=prior.axial_stiffness_n * math.exp(rng.uniform(-0.7, 0.7)),
        sigma_n_per_mm2=prior.sigma_n_per_mm2 * math.exp(rng.uniform(-0.7, 0.7)),
        mu=rng.uniform(0.12, 0.3), fsc_n_per_mm=prior.fsc_n_per_mm * rng.uniform(0.5, 1.6))
    zeros = tuple(float(v) for v in rng.normal(0.0, 0.002, 4))
    return Plant(params, {e: random_effect_values(e, rng) for e in effect_ids}, zeros)


def draw_cases(count: int, seed: int, prior: CatheterParams) -> list[BlindCase]:
    """`count` cases: about 20 % clean, 15 % pairs, the rest single effects cycling through the catalog;
    tracker noise 0.05-0.2 mm per axis and 0-2 % dropout."""
    rng = np.random.default_rng(seed)
    n_clean = round(CLEAN_FRACTION * count)
    n_pair = round(PAIR_FRACTION * count)
    ids = list(EFFECTS)
    order = [str(e) for e in rng.permutation(ids)]
    kinds = ["none"] * n_clean + ["pair"] * n_pair + ["single"] * (count - n_clean - n_pair)
    kinds = [kinds[i] for i in rng.permutation(count)]
    cases = []
    singles = 0
    for index, kind in enumerate(kinds):
        if kind == "single":
            chosen = (order[singles % len(order)],)
            singles += 1
        elif kind == "pair":
            chosen = tuple(str(e) for e in rng.choice(ids, size=2, replace=False))
        else:
            chosen = ()
        case_seed = int(rng.integers(2 ** 31))
        case_rng = np.random.default_rng(case_seed)
        noise_mm, dropout = case_rng.uniform(0.05, 0.2), case_rng.uniform(0.0, 0.02)
        cases.append(BlindCase(index, kind, random_plant(prior, chosen, case_rng), noise_mm, dropout, case_seed))
    return cases


def write_plant_config(case: BlindCase, folder: Path) -> Path:
    """The case's plant as a virtual-plant description (configs/virtual_plant.toml's format) and its
    catheter TOML, in `folder`; returns the description's path."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "catheter.toml").write_text(case.plant.params.to_toml())
    effects = []
    for effect_id, values in case.plant.effects.items():
        named = ", ".join(f"{name} = {float(value)!r}" for name, value in zip(effect(effect_id).param_names, values))
        effects.append(f"{effect_id} = {{ {named} }}")
    lines = ['catheter = "catheter.toml"', f"n_elements = {case.plant.n_elements}",
             f"tendon_zero_offsets_mm = [{', '.join(repr(float(v)) for v in case.plant.zero_offsets_mm)}]", "",
             "[effects]", *effects, "",
             "[tracker]", f"noise_mm = {case.tracker_noise_mm!r}", f"dropout = {case.tracker_dropout!r}",
             f"seed = {case.seed}", ""]
    path = folder / "virtual_plant.toml"
    path.write_text("\n".join(lines))
    return path


def record_case(case: BlindCase, folder: Path, config: TestbedConfig, plan: ExcitationPlan,
                prior: CatheterParams) -> tuple[BlindCase, Path, Path]:
    """Training and held-out logs of the case's plant on the virtual testbed, as `crest excite` records
    them (in a process of its own, see `call_isolated`); a plant whose solver fails is redrawn (same
    effects)."""
    for redraw in range(MAX_REDRAWS + 1):
        if redraw:
            rng = np.random.default_rng(case.seed + 7919 * redraw)
            case = BlindCase(case.index, case.kind, random_plant(prior, case.effects, rng), case.tracker_noise_mm,
                             case.tracker_dropout, case.seed, redraw)
        options = SessionOptions(config=config, plant_config=write_plant_config(case, folder / f"plant_{redraw}"),
                                 realtime=False)
        try:
            results = call_isolated(_record, options, plan, folder / f"logs_{redraw}", prior,
                                    timeout_s=RECORD_TIMEOUT_S)
        except (PlantFailure, CallTimedOut):
            continue
        if all(r.tip_samples >= MIN_TIP_FRACTION_BEYOND_DROPOUT * (1.0 - case.tracker_dropout) * r.tracker_frames
               for r in results.values()):
            return case, results["train"].log_path, results["holdout"].log_path
    raise PlantFailure(f"blind case {case.index}: the plant failed in {MAX_REDRAWS + 1} draws")


def _record(options: SessionOptions, plan: ExcitationPlan, folder: Path, prior: CatheterParams) -> dict:
    try:
        with open_session(options) as session:
            return record_excitation(session, plan, folder, prior)
    except SafetyStop as stop:      # a diverged plant reported absurd tensions
        raise PlantFailure(str(stop)) from None


def oracle_shrinks(case: BlindCase, train: Path, holdout: Path, prior: CatheterParams, baseline_rmse_mm: float,
                   settings: DiagnosisSettings) -> tuple[float, float, float]:
    """The held-out shrink 1 - RMSE / baseline RMSE when the true effects are added, two ways, and
    the size of the effects:

    fitted (the oracle the prediction is scored against): the true effects added to the model and
    calibrated with the base parameters on the training log, from the true plant's values, as the
    diagnosis fits a candidate (where that fit ends worse on the training log than the true plant
    itself, a local minimum, the true plant is the oracle); exact: the true plant simulated at the
    diagnosis' resolution (it also carries the difference between that resolution and the
    plant's); effect size: the RMS distance on the held-out log between the true plant's tip with
    and without its effects.
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
    fitted_shrink, exact_shrink = (1.0 - rmse_mm(errors) / baseline_rmse_mm
                                   for errors in (tip_errors(fitted, held, res), truth_errors))
    return fitted_shrink, exact_shrink, effect_rms_mm


def run_case(case: BlindCase, folder: Path, config: TestbedConfig, plan: ExcitationPlan,
             prior: CatheterParams, settings: DiagnosisSettings) -> dict:
    """Record, diagnose blind, and compare with the truth. A plant that keeps failing is skipped (reported)."""
    start = time.perf_counter()
    try:
        case, train, holdout = record_case(case, folder, config, plan, prior)
    except PlantFailure as error:
        return {"case": case.index, "kind": case.kind, "truth": list(case.effects), "skipped": str(error)}
    recorded = time.perf_counter()
    try:
        result = call_isolated(diagnose_logs, [train], [holdout], settings=settings, timeout_s=DIAGNOSIS_TIMEOUT_S)
    except CallTimedOut as error:
        return {"case": case.index, "kind": case.kind, "truth": list(case.effects), "redraws": case.redraws,
                "record_seconds": recorded - start, "no_result": str(error)}
    seconds = time.perf_counter() - recorded
    verdict = result["verdict"]
    oracle, exact, effect_rms_mm = oracle_shrinks(case, train, holdout, prior, verdict["holdout_rmse_before_mm"],
                                                  settings)
    return {"case": case.index, "kind": case.kind, "truth": list(case.effects),
            "truth_params": {k: list(v) for k, v in case.plant.effects.items()},
            "noise_mm": case.tracker_noise_mm, "dropout": case.tracker_dropout, "redraws": case.redraws,
            "predicted": verdict["effect"], "predicted_effects": verdict["effects"],
            "holdout_rmse_before_mm": verdict["holdout_rmse_before_mm"],
            "holdout_rmse_after_mm": verdict["holdout_rmse_after_mm"],
            "noise_floor_mm": result["baseline"]["noise_floor_mm"],
            "predicted_shrink": verdict["shrink"], "oracle_shrink": oracle, "exact_truth_shrink": exact,
            "effect_rms_mm": effect_rms_mm, "above_noise": effect_rms_mm >= math.sqrt(3.0) * case.tracker_noise_mm,
            "shrink_error_pp": 100.0 * abs(verdict["shrink"] - oracle),
            "top_candidates": [c["effect"] for c in result["candidates"][:3]],
            "record_seconds": recorded - start, "seconds": seconds, "timing_s": result["timing_s"],
            "slowest_candidate": max(result["candidates"], key=lambda c: c["seconds"])["effect"]}


def score(all_rows: list[dict]) -> dict:
    """Confusion matrix and accuracies (see module doc). Skipped cases (no plant could be recorded) are
    counted, not scored; a case whose diagnosis gave no result counts as wrong (verdict NO_RESULT)
    and has no shrink error."""
    rows = [r if "no_result" not in r else {**r, "predicted": NO_RESULT, "predicted_effects": []}
            for r in all_rows if "skipped" not in r]
    labels = list(EFFECTS) + ["none", NO_RESULT]
    confusion = {t: {p: 0 for p in labels} for t in labels[:-1]}
    for row in rows:
        if row["kind"] in ("single", "none"):
            truth = row["truth"][0] if row["truth"] else "none"
            confusion[truth][row["predicted"]] += 1
    singles = [r for r in rows if r["kind"] == "single"]
    audible = [r for r in singles if r.get("above_noise", True)]     # a case without a result counts
    clean = [r for r in rows if r["kind"] == "none"]
    pairs = [r for r in rows if r["kind"] == "pair"]
    errors = [r["shrink_error_pp"] for r in rows if "shrink_error_pp" in r]

    def fraction(hits: list[bool]) -> float | None:
        return float(np.mean(hits)) if hits else None

    return {
        "cases": len(all_rows),
        "top1_single": fraction([r["predicted"] == r["truth"][0] for r in singles]),
        "top1_single_above_noise": fraction([r["predicted"] == r["truth"][0] for r in audible]),
        "none_clean": fraction([r["predicted"] == "none" for r in clean]),
        "pair_exact": fraction([sorted(r["predicted_effects"]) == sorted(r["truth"]) for r in pairs]),
        "pair_any_found": fraction([bool(set(r["predicted_effects"]) & set(r["truth"])) for r in pairs]),
        "shrink_error_pp": {"mean": float(np.mean(errors)), "median": float(np.median(errors)),
                            "max": float(np.max(errors)),
                            "within_10pp": float(np.mean([e <= 10.0 for e in errors]))} if errors else None,
        "confusion": confusion,
        "counts": {"single": len(singles), "single_below_noise": len(singles) - len(audible),
                   "none": len(clean), "pair": len(pairs),
                   "skipped": len(all_rows) - len(rows), "no_result": sum("no_result" in r for r in rows)},
        "targets": TARGETS,
    }


def run_blind_benchmark(cases: int = 40, seed: int = 0, *, short: bool = False,
                        settings: DiagnosisSettings = DiagnosisSettings(), work_dir: Path | str | None = None,
                        parallel_cases: int = PARALLEL_CASES, progress: Callable[[str], None] | None = None) -> dict:
    """Draw, record, diagnose and score `cases` blind cases; returns {"score", "cases", "settings"}.

    work_dir keeps each case's plant description and logs (default: a temporary folder).
    parallel_cases: cases run at once (each records and diagnoses in processes of its own).
    """
    say = progress or (lambda message: None)
    prior = CatheterParams.from_toml()
    config = load_testbed_config()
    plan = plan_excitation(config, prior, short=short)
    rows = []
    clock = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="crest-blind-") as scratch:
        root = Path(work_dir) if work_dir else Path(scratch)

        def run(case: BlindCase) -> dict:
            return run_case(case, root / f"case_{case.index:03d}", config, plan, prior, settings)

        with ThreadPoolExecutor(parallel_cases) as pool:
            for row in pool.map(run, draw_cases(cases, seed, prior)):
                rows.append(row)
                elapsed = time.perf_counter() - clock
                eta = elapsed / len(rows) * (cases - len(rows))
                head = f"blind case {row['case'] + 1}/{cases} ({elapsed / 60:.0f} min, about {eta / 60:.0f} min left)"
                (root / "cases.json").write_text(json.dumps(rows, indent=1))    # kept should the run be cut short
                if "skipped" in row or "no_result" in row:
                    say(f"{head}: truth {'+'.join(row['truth']) or 'none'}, {row.get('skipped') or row['no_result']}")
                    continue
                say(f"{head}: truth {'+'.join(row['truth']) or 'none'}, verdict "
                    f"{'+'.join(row['predicted_effects']) or 'none'}, shrink {row['predicted_shrink']:.2f} "
                    f"(oracle {row['oracle_shrink']:.2f}), recorded in {row['record_seconds']:.0f} s, "
                    f"diagnosed in {row['seconds']:.0f} s")
    total = time.perf_counter() - clock
    return {"score": score(rows), "cases": rows,
            "settings": {"cases": cases, "seed": seed, "excitation": "short" if short else "standard",
                         "path": "virtual testbed, crest excite", "seconds": total,
                         "seconds_per_case": total / max(1, cases)}}
