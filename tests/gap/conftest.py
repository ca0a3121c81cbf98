"""Short, fixed-seed gap cases: a model plant records the short excitation, the diagnosis reads the logs."""
from __future__ import annotations

import fcntl
import functools
import os
import pickle
import tempfile
from pathlib import Path

import numpy as np

from control.excitation import holdout_trajectory, training_trajectory
from crest.config import load_testbed_config
from crest.experiment.workspace_from_config import limits_for, workspace_for
from crest.gap.log_diagnosis import diagnose_logs
from crest.gap.synthetic_logs import Plant, SensorNoise, record_plant_log
from model import CatheterParams
from model.effects import EFFECTS
from model.gap.diagnosis import DiagnosisSettings
from model.gap.simulation import Resolution
from tests.conftest import SHARED_DIR_VARIABLE

# Coarser and shorter than the defaults, so that ten diagnoses fit in the test budget.
TEST_SETTINGS = DiagnosisSettings(resolution=Resolution(n_elements=6, fit_rate_hz=5.0), baseline_iterations=25,
                                  candidate_iterations=10, pair_candidates=1)
SAMPLE_RATE_HZ = 20.0
# The plant differs from the prior catheter (configs/catheter.toml) that the diagnosis starts from.
PLANT_CHANGES = {"bending_stiffness_nmm2": 1100.0, "mu": 0.24, "sigma_n_per_mm2": 0.7, "fsc_n_per_mm": 0.006}


def prior() -> CatheterParams:
    return CatheterParams.from_toml()


def record_case(folder: Path, effects: dict, seed: int = 1, noise_mm: float = 0.1) -> tuple[Path, Path]:
    """Training and held-out logs of a plant with `effects` ({id: values}, typical values for None)."""
    params = prior()
    config = load_testbed_config()
    workspace, limits, period_s = workspace_for(config, params), limits_for(config), 1.0 / SAMPLE_RATE_HZ
    plant = Plant(params.replace(**PLANT_CHANGES),
                  {e: EFFECTS[e].typical if v is None else v for e, v in effects.items()}, n_elements=10)
    rng = np.random.default_rng(seed)
    noise = SensorNoise(tip_mm=noise_mm, dropout_fraction=0.01)
    train = record_plant_log(folder / "train.csv", training_trajectory(workspace, limits, period_s, short=True),
                             plant, noise, rng)
    holdout = record_plant_log(folder / "holdout.csv", holdout_trajectory(workspace, limits, period_s, short=True),
                               plant, noise, rng)
    return train, holdout


@functools.cache
def diagnosed(effect_id: str | None) -> dict:
    """The diagnosis of the fixed-seed case with this effect (None: clean), computed once per test run.

    Under pytest-xdist the tests that read one diagnosis may run on different workers: the first to
    ask computes it, holding a lock on its file in the run's shared folder (tests/conftest.py), and
    the others wait on that lock and read the file. Run alone, it is computed once per process."""
    shared = os.environ.get(SHARED_DIR_VARIABLE)
    if shared is None:
        return _diagnosis(effect_id)
    path = Path(shared) / f"diagnosis-{effect_id or 'clean'}.pickle"
    with open(path.with_suffix(".lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not path.is_file():
            path.write_bytes(pickle.dumps(_diagnosis(effect_id)))
        return pickle.loads(path.read_bytes())


def _diagnosis(effect_id: str | None) -> dict:
    with tempfile.TemporaryDirectory() as folder:
        train, holdout = record_case(Path(folder), {} if effect_id is None else {effect_id: None})
        return diagnose_logs([train], [holdout], settings=TEST_SETTINGS)
