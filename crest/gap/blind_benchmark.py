"""Blind validation of the gap diagnosis on data whose effect is withheld.

Per case: draw an effect (or none, or two) with random parameters, a plant whose base
parameters and tendon zeros differ from the prior catheter, and random sensor noise; record a
training and a held-out log of the standard excitation through the log writer; diagnose from
the two files alone (`diagnose_logs` sees paths, never the draw); score against the draw.

Scores: confusion matrix (true id -> verdict.effect, single and clean cases), top-1 accuracy on
single effects, `none` accuracy on clean cases, pair accuracy (verdict.effects equals the true
pair; and at least one found), and the error of the predicted shrink against the oracle shrink
1 - RMSE(true plant model) / RMSE(baseline) on the held-out log, where the true plant model is
the drawn parameters and effects simulated at the diagnosis' resolution.
"""
from __future__ import annotations

import math
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from control.excitation import ExcitationGeometry, holdout_trajectory, training_trajectory
from crest.gap.log_diagnosis import diagnose_logs
from crest.gap.log_recordings import load_recordings
from crest.gap.synthetic_logs import Plant, SensorNoise, record_plant_log
from model import CatheterParams, ModelSolverError
from model.effects import EFFECTS, effect
from model.gap.calibration import ModelFit, rmse_mm, tip_errors
from model.gap.diagnosis import DiagnosisSettings
from model.gap.simulation import catheter_for

CLEAN_FRACTION = 0.2
PAIR_FRACTION = 0.15
MAX_REDRAWS = 5
TARGETS = {"top1_single": 0.9, "none_clean": 0.8, "shrink_error_pp": 10.0}


@dataclass(frozen=True)
class BlindCase:
    """The hidden truth of one case."""

    index: int
    kind: str                     # "single", "none" or "pair"
    plant: Plant
    noise: SensorNoise
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
        g = 9.81 * rng.uniform(0.8, 1.6)
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
    """`count` cases: about 20 % clean, 15 % pairs, the rest single effects cycling through the catalog."""
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
        noise = SensorNoise(tip_mm=case_rng.uniform(0.05, 0.2), dropout_fraction=case_rng.uniform(0.0, 0.02))
        cases.append(BlindCase(index, kind, random_plant(prior, chosen, case_rng), noise, case_seed))
    return cases


def record_case(case: BlindCase, folder: Path, prior: CatheterParams, short: bool) -> tuple[BlindCase, Path, Path]:
    """Training and held-out logs of the case's plant; a plant that diverges is redrawn (same effects)."""
    geometry = ExcitationGeometry.from_params(prior)
    for redraw in range(MAX_REDRAWS + 1):
        rng = np.random.default_rng(case.seed + 7919 * redraw)
        plant = case.plant if redraw == 0 else random_plant(prior, case.effects, rng)
        try:
            train = record_plant_log(folder / "train.csv", training_trajectory(geometry, short=short), plant,
                                     case.noise, rng, overwrite=True)
            holdout = record_plant_log(folder / "holdout.csv", holdout_trajectory(geometry, short=short), plant,
                                       case.noise, rng, overwrite=True)
            return BlindCase(case.index, case.kind, plant, case.noise, case.seed, redraw), train, holdout
        except ModelSolverError:
            continue
    raise ModelSolverError(f"blind case {case.index}: the plant diverged in {MAX_REDRAWS + 1} draws")


def oracle_shrink(case: BlindCase, holdout: Path, baseline_rmse_mm: float, settings: DiagnosisSettings) -> float:
    """1 - RMSE of the true plant model (at the diagnosis resolution) / baseline RMSE, on the held-out log."""
    held = settings.resolution.prepare(load_recordings([holdout]))
    truth = ModelFit(catheter_for(case.plant.params, held), case.plant.zero_offsets_mm, dict(case.plant.effects))
    return 1.0 - rmse_mm(tip_errors(truth, held, settings.resolution)) / baseline_rmse_mm


def run_case(case: BlindCase, folder: Path, prior: CatheterParams, settings: DiagnosisSettings,
             short: bool) -> dict:
    """Record, diagnose blind, and compare with the truth. A plant that keeps diverging is skipped (reported)."""
    try:
        case, train, holdout = record_case(case, folder, prior, short)
    except ModelSolverError as error:
        return {"case": case.index, "kind": case.kind, "truth": list(case.effects), "skipped": str(error)}
    start = time.perf_counter()
    result = diagnose_logs([train], [holdout], settings=settings)
    seconds = time.perf_counter() - start
    verdict = result["verdict"]
    oracle = oracle_shrink(case, holdout, verdict["holdout_rmse_before_mm"], settings)
    return {"case": case.index, "kind": case.kind, "truth": list(case.effects),
            "truth_params": {k: list(v) for k, v in case.plant.effects.items()},
            "noise_mm": case.noise.tip_mm, "redraws": case.redraws,
            "predicted": verdict["effect"], "predicted_effects": verdict["effects"],
            "holdout_rmse_before_mm": verdict["holdout_rmse_before_mm"],
            "holdout_rmse_after_mm": verdict["holdout_rmse_after_mm"],
            "predicted_shrink": verdict["shrink"], "oracle_shrink": oracle,
            "shrink_error_pp": 100.0 * abs(verdict["shrink"] - oracle),
            "top_candidates": [c["effect"] for c in result["candidates"][:3]], "seconds": seconds,
            "timing_s": result["timing_s"],
            "slowest_candidate": max(result["candidates"], key=lambda c: c["seconds"])["effect"]}


def score(all_rows: list[dict]) -> dict:
    """Confusion matrix and accuracies (see module doc); skipped cases are counted, not scored."""
    rows = [r for r in all_rows if "skipped" not in r]
    labels = list(EFFECTS) + ["none"]
    confusion = {t: {p: 0 for p in labels} for t in labels}
    for row in rows:
        if row["kind"] in ("single", "none"):
            truth = row["truth"][0] if row["truth"] else "none"
            confusion[truth][row["predicted"]] += 1
    singles = [r for r in rows if r["kind"] == "single"]
    clean = [r for r in rows if r["kind"] == "none"]
    pairs = [r for r in rows if r["kind"] == "pair"]
    errors = [r["shrink_error_pp"] for r in rows]

    def fraction(hits: list[bool]) -> float | None:
        return float(np.mean(hits)) if hits else None

    return {
        "cases": len(all_rows),
        "top1_single": fraction([r["predicted"] == r["truth"][0] for r in singles]),
        "none_clean": fraction([r["predicted"] == "none" for r in clean]),
        "pair_exact": fraction([sorted(r["predicted_effects"]) == sorted(r["truth"]) for r in pairs]),
        "pair_any_found": fraction([bool(set(r["predicted_effects"]) & set(r["truth"])) for r in pairs]),
        "shrink_error_pp": {"mean": float(np.mean(errors)), "median": float(np.median(errors)),
                            "max": float(np.max(errors)),
                            "within_10pp": float(np.mean([e <= 10.0 for e in errors]))} if errors else None,
        "confusion": confusion,
        "counts": {"single": len(singles), "none": len(clean), "pair": len(pairs),
                   "skipped": len(all_rows) - len(rows)},
        "targets": TARGETS,
    }


def run_blind_benchmark(cases: int = 40, seed: int = 0, *, short: bool = False,
                        settings: DiagnosisSettings = DiagnosisSettings(), work_dir: Path | str | None = None,
                        progress: Callable[[str], None] | None = None) -> dict:
    """Draw, record, diagnose and score `cases` blind cases; returns {"score", "cases", "settings"}."""
    say = progress or (lambda message: None)
    prior = CatheterParams.from_toml()
    rows = []
    with tempfile.TemporaryDirectory(prefix="crest-blind-") as scratch:
        root = Path(work_dir) if work_dir else Path(scratch)
        for case in draw_cases(cases, seed, prior):
            folder = root / f"case_{case.index:03d}"
            folder.mkdir(parents=True, exist_ok=True)
            rows.append(run_case(case, folder, prior, settings, short))
            row = rows[-1]
            if "skipped" in row:
                say(f"blind case {case.index + 1}/{cases}: skipped, {row['skipped']}")
                continue
            say(f"blind case {case.index + 1}/{cases}: truth {'+'.join(row['truth']) or 'none'}, "
                f"verdict {'+'.join(row['predicted_effects']) or 'none'}, shrink {row['predicted_shrink']:.2f} "
                f"(oracle {row['oracle_shrink']:.2f}), {row['seconds']:.0f} s")
    return {"score": score(rows), "cases": rows,
            "settings": {"cases": cases, "seed": seed, "excitation": "short" if short else "standard"}}
