"""How long the gap diagnosis takes on three long logs (for `crest bench`; no timing asserts in tests).

- synthetic: a model plant (the prior with mu changed, backlash, exact tendon zeros) records the
  standard training excitation repeated to `duration_s` at `sample_rate_hz`, and the standard
  held-out excitation, directly (`crest.gap.synthetic_logs`): the easy case.
- virtual_testbed: a randomly drawn plant (base parameters 10-20 % off the prior, non-zero tendon
  zeros, one effect, tracker noise and dropout) recorded through the virtual testbed as `crest
  excite` records, 10 minutes of training at 100 Hz; recorded once per seed and cached
  (`crest.gap.testbed_bench_log`).
- real: the longest real log in ../shared/data (`crest.gap.real_bench_log`); skipped, with the
  reason, where that folder is absent.

Per log: the wall-clock seconds of reading both logs and the whole diagnosis, its phases
(`timing_s` of the diagnosis: baseline, candidates, pairs, where), and the Newton iterations per
sample of the quasi-static solver, counted by the model (`model.gap.simulation.solver_work`) in one
run of the baseline fit along the samples the fits see (training) and along the held-out log.
"""
from __future__ import annotations

import math
import os
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from control.excitation import holdout_trajectory, training_trajectory
from crest.config import load_testbed_config
from crest.experiment.workspace_from_config import limits_for, workspace_for
from crest.gap.log_diagnosis import diagnose_logs
from crest.gap.log_recordings import load_recordings
from crest.gap.real_bench_log import real_data_missing, real_logs
from crest.gap.synthetic_logs import Plant, SensorNoise, record_plant_log
from crest.gap.testbed_bench_log import cache_folder, testbed_logs
from model import CatheterParams
from model.gap.calibration import ModelFit
from model.gap.diagnosis import DiagnosisSettings
from model.gap.simulation import Resolution, solver_work

GOAL_S = 60.0


def timed_diagnosis(train: Path, holdout: Path, workers: int = 2) -> dict:
    """Seconds, phases, verdict and Newton iterations per sample of the diagnosis of the two logs."""
    settings = DiagnosisSettings(workers=workers)
    start = time.perf_counter()
    result = diagnose_logs([train], [holdout], settings=settings)
    seconds = time.perf_counter() - start
    recordings = {"train": load_recordings([train]), "holdout": load_recordings([holdout])}
    return {"seconds": seconds, "goal_s": GOAL_S, "met": seconds <= GOAL_S, "workers": workers,
            "cpu_count": os.cpu_count(), "stages_s": result["timing_s"],
            "rows": {name: sum(len(r) for r in rs) for name, rs in recordings.items()},
            "newton_iterations_per_sample": newton_iterations_per_sample(
                ModelFit.from_dict(result["baseline"]["fit"]), recordings["train"], recordings["holdout"],
                settings.resolution),
            "verdict": result["verdict"]["effect"], "effects": result["verdict"]["effects"],
            "top_candidates": [c["effect"] for c in result["candidates"][:3]], "rejected": result["verdict"]["rejected"],
            "shrink": result["verdict"]["shrink"], "baseline_holdout_rmse_mm": result["baseline"]["holdout_rmse_mm"],
            "sampling": result.get("sampling"), "resolution": result["settings"]["resolution"]}


def newton_iterations_per_sample(fit: ModelFit, train: Sequence, holdout: Sequence, res: Resolution) -> dict:
    """Newton iterations per sample of one model run at the fit, along the fits' training samples and
    along the held-out samples (at the fit resolution), with the sample counts."""
    zeros = np.asarray(fit.zero_offsets_mm)
    counts = {}
    for name, recordings in (("train", res.prepare_training(train)), ("holdout", res.prepare(holdout))):
        samples = sum(len(r) for r in recordings)
        iterations = solver_work(fit.params, fit.terms(), zeros, recordings, res)
        counts[name] = {"per_sample": iterations / samples, "samples": samples}
    return counts


def synthetic_diagnosis(duration_s: float = 600.0, sample_rate_hz: float = 100.0, workers: int = 2,
                        seed: int = 0) -> dict:
    """The easy case: see module doc."""
    params = CatheterParams.from_toml()
    config = load_testbed_config()
    workspace, limits, period_s = workspace_for(config, params), limits_for(config), 1.0 / sample_rate_hz
    one = training_trajectory(workspace, limits, period_s)
    plant = Plant(params.replace(mu=0.25), {"backlash": (0.4,)})
    rng = np.random.default_rng(seed)
    with tempfile.TemporaryDirectory(prefix="crest-gap-bench-") as folder:
        train = record_plant_log(Path(folder) / "train.csv", one.repeated(math.ceil(duration_s / one.duration_s)),
                                 plant, SensorNoise(), rng)
        holdout = record_plant_log(Path(folder) / "holdout.csv", holdout_trajectory(workspace, limits, period_s),
                                   plant, SensorNoise(), rng)
        return {**timed_diagnosis(train, holdout, workers), "log": "model plant: prior with mu 0.25, backlash "
                "0.4 mm, exact tendon zeros", "train_duration_s": duration_s, "sample_rate_hz": sample_rate_hz}


def testbed_diagnosis(seed: int = 0, duration_s: float = 600.0, workers: int = 2,
                      progress: Callable[[str], None] | None = None) -> dict:
    """The randomly drawn plant on the virtual testbed: see module doc."""
    say = progress or (lambda message: None)
    folder = cache_folder(seed, duration_s)
    say(f"virtual-testbed log: {'from the cache' if (folder / 'plant.json').exists() else 'recording it once'} "
        f"({folder})")
    logs = testbed_logs(seed, duration_s)
    return {**timed_diagnosis(logs.train, logs.holdout, workers), "plant": logs.plant,
            "log": f"virtual testbed, seed {seed}, " + (f"from the cache {folder}" if logs.cached else
                                                       f"recorded now and cached in {folder}"),
            "cached": logs.cached}


def real_diagnosis(data_dir: Path | None = None, workers: int = 2) -> dict:
    """The longest real log: see module doc; {"skipped": reason} without the data."""
    missing = real_data_missing(data_dir)
    if missing:
        return {"skipped": f"skipped: {missing}"}
    with tempfile.TemporaryDirectory(prefix="crest-gap-real-") as folder:
        logs = real_logs(Path(folder), data_dir)
        return {**timed_diagnosis(logs.train, logs.holdout, workers),
                "log": f"real: {logs.train.name} ({logs.train_rows} rows) held out on {logs.holdout.name} "
                       f"({logs.holdout_rows} rows)", "import_warnings": logs.import_warnings}


CASES = ("synthetic", "virtual_testbed", "real")


def diagnosis_benchmarks(seed: int = 0, data_dir: Path | None = None, workers: int = 2,
                         progress: Callable[[str], None] | None = None, cases: Sequence[str] = CASES) -> dict:
    """The cases of the module doc (all, or those named in `cases`), one after the other."""
    say = progress or (lambda message: None)
    runs = {"synthetic": lambda: synthetic_diagnosis(workers=workers, seed=seed),
            "virtual_testbed": lambda: testbed_diagnosis(seed, workers=workers, progress=say),
            "real": lambda: real_diagnosis(data_dir, workers)}
    results = {}
    for case in CASES:
        if case in cases:
            say(f"gap: {case.replace('_', '-')} log")
            results[case] = runs[case]()
    return results
