"""The realistic benchmark log: a 10-minute excitation recorded through the virtual testbed from a
randomly drawn plant, recorded once per seed and kept in the user's cache folder.

The plant (drawn from `seed`, `draw_plant`): every base parameter 10-20 % off the prior catheter
(factor 1 +- U(0.10, 0.20), sign drawn), tendon zeros of a few micrometres as the blind benchmark
draws them (about 1 N of pretension), one catalog effect drawn with its magnitude from the blind
benchmark's range table, tracker noise 0.05-0.2 mm per axis and 0-2 % dropout. It is written as a
plant description and recorded as `crest excite` records (`record_excitation` on the virtual
testbed: CiA 402 drives, the plant behind them, the tracker; in simulated time): the standard
training excitation repeated to at least `duration_s`, and the standard held-out excitation, at
the SYNC rate (100 Hz). Recording takes minutes, so the logs are kept in
<cache>/crest/gap-bench/<RECIPE>-seed<seed>-<duration>s/ (cache: $XDG_CACHE_HOME or ~/.cache) and
reused; delete that folder to record them again.
"""
from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from crest.config import load_testbed_config
from crest.driver import SafetyStop
from crest.experiment.excitation_run import ExcitationPlan, plan_excitation, record_excitation
from crest.gap.blind_benchmark import BlindCase, write_plant_config
from crest.gap.effect_draws import DAHL_EFFECT_RANGES, catalog_ids, draw_effect
from crest.gap.isolated_call import call_isolated
from crest.gap.synthetic_logs import Plant
from crest.session import SessionOptions, open_session
from model import CatheterParams
from model.effects import effect

RECIPE = "testbed-v2"   # change when the draw, the plant or the recording changes: the cache is then re-recorded
                        # (v2: the tracker offset turns with the tip, 82d9cb6)
RECORD_TIMEOUT_S = 3600.0
OFF_PRIOR = ("bending_stiffness_nmm2", "axial_stiffness_n", "sigma_n_per_mm2", "mu", "fsc_n_per_mm")


@dataclass(frozen=True)
class BenchLogs:
    """The recorded pair of logs, the drawn plant's description and whether they came from the cache."""

    train: Path
    holdout: Path
    plant: dict
    cached: bool


def cache_folder(seed: int, duration_s: float) -> Path:
    root = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return root / "crest" / "gap-bench" / f"{RECIPE}-seed{seed}-{duration_s:.0f}s"


def draw_plant(prior: CatheterParams, rng: np.random.Generator) -> tuple[Plant, float, float]:
    """The plant, the tracker noise (mm per axis) and dropout fraction (see module doc)."""
    factors = {name: 1.0 + float(rng.choice([-1.0, 1.0])) * float(rng.uniform(0.10, 0.20)) for name in OFF_PRIOR}
    params = prior.replace(**{name: getattr(prior, name) * factor for name, factor in factors.items()})
    zeros = tuple(float(v) for v in rng.normal(0.0, 0.002, 4))
    effect_id = str(rng.choice(catalog_ids(DAHL_EFFECT_RANGES)))
    values = effect(effect_id).values_from(draw_effect(DAHL_EFFECT_RANGES, effect_id, rng))
    return Plant(params, {effect_id: values}, zeros), float(rng.uniform(0.05, 0.2)), float(rng.uniform(0.0, 0.02))


def testbed_logs(seed: int = 0, duration_s: float = 600.0) -> BenchLogs:
    """The cached logs for this seed, recorded first if they are not in the cache."""
    folder = cache_folder(seed, duration_s)
    described = folder / "plant.json"
    if described.exists():
        return BenchLogs(folder / "logs" / "train.csv", folder / "logs" / "holdout.csv",
                         json.loads(described.read_text()), cached=True)
    prior = CatheterParams.from_toml()
    config = load_testbed_config()
    standard = plan_excitation(config, prior)
    train = standard.logs["train"]
    plan = ExcitationPlan(standard.conditioning, {"train": train.repeated(math.ceil(duration_s / train.duration_s)),
                                                  "holdout": standard.logs["holdout"]})
    plant, noise_mm, dropout = draw_plant(prior, np.random.default_rng(seed))
    case = BlindCase(0, "single", plant, noise_mm, dropout, seed)
    options = SessionOptions(config=config, plant_config=write_plant_config(case, folder / "plant"), realtime=False,
                             in_process=True)
    results = call_isolated(_record, options, plan, folder / "logs", prior, timeout_s=RECORD_TIMEOUT_S)
    description = {"effects": {k: list(v) for k, v in plant.effects.items()},
                   "parameter_factors": {name: getattr(plant.params, name) / getattr(prior, name)
                                         for name in OFF_PRIOR},
                   "tendon_zero_offsets_mm": list(plant.zero_offsets_mm), "tracker_noise_mm": noise_mm,
                   "tracker_dropout": dropout, "seed": seed, "recipe": RECIPE,
                   "train_duration_s": plan.logs["train"].duration_s,
                   "holdout_duration_s": plan.logs["holdout"].duration_s}
    described.write_text(json.dumps(description, indent=1))        # last: a broken recording is not cached
    return BenchLogs(results["train"].log_path, results["holdout"].log_path, description, cached=False)


def _record(options: SessionOptions, plan: ExcitationPlan, folder: Path, prior: CatheterParams) -> dict:
    try:
        with open_session(options) as session:
            return record_excitation(session, plan, folder, prior, overwrite=True)
    except SafetyStop as stop:
        raise RuntimeError(f"the benchmark plant failed while recording ({stop}); change RECIPE's draw "
                           "or the seed") from None
