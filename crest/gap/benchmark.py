"""How long the gap diagnosis takes on a long log (for `crest bench`; no timing asserts in tests).

The case: a model plant with backlash records the standard training excitation repeated to
`duration_s` at `sample_rate_hz` and the standard held-out excitation; the clock covers reading
both logs and the whole diagnosis (baseline, all candidates in parallel, pairs, regions).
"""
from __future__ import annotations

import math
import os
import tempfile
import time
from pathlib import Path

import numpy as np

from control.excitation import holdout_trajectory, training_trajectory
from crest.config import load_testbed_config
from crest.experiment.workspace_from_config import limits_for, workspace_for
from crest.gap.log_diagnosis import diagnose_logs
from crest.gap.synthetic_logs import Plant, SensorNoise, record_plant_log
from model import CatheterParams
from model.gap.diagnosis import DiagnosisSettings

GOAL_S = 60.0


def diagnosis_time(duration_s: float = 600.0, sample_rate_hz: float = 100.0, workers: int = 2,
                   seed: int = 0) -> dict:
    """Seconds to diagnose a `duration_s` training log plus the standard held-out log, with the verdict."""
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
        start = time.perf_counter()
        result = diagnose_logs([train], [holdout], settings=DiagnosisSettings(workers=workers))
        seconds = time.perf_counter() - start
    return {"seconds": seconds, "goal_s": GOAL_S, "met": seconds <= GOAL_S, "train_duration_s": duration_s,
            "sample_rate_hz": sample_rate_hz, "workers": workers, "cpu_count": os.cpu_count(),
            "stages_s": result["timing_s"], "verdict": result["verdict"]["effect"],
            "shrink": result["verdict"]["shrink"], "resolution": result["settings"]["resolution"]}
