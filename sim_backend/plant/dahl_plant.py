"""The default plant: the lumped Dahl catheter of `model`, with switchable unmodelled effects."""
from __future__ import annotations

import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from configs import CONFIG_DIR
from model import CatheterParams, DahlCatheter, EffectTerms
from model.dahl_catheter import MAX_DYNAMIC_SAMPLE_S
from model.effects import combined_terms

DEFAULT_PLANT_TOML = CONFIG_DIR / "virtual_plant.toml"


class PlantConfigError(ValueError):
    """The virtual plant's configuration is invalid; the message names the file and field."""


@dataclass(frozen=True)
class PlantConfig:
    """What the virtual testbed's catheter is: parameters, mismatch, effects, tracker noise.

    tendon_zero_offsets_mm: where each tendon's just-taut position lies from its drive's zero;
    the catheter sees u_k - zero_k (a real testbed's homing leaves such offsets of micrometres,
    a newton of pretension each on stiff tendons).
    """

    params: CatheterParams = field(default_factory=CatheterParams)
    n_elements: int = 20
    effects: dict = field(default_factory=dict)   # {effect id: {param: value}}
    tracker_noise_mm: float = 0.05
    tracker_dropout: float = 0.0
    tracker_seed: int = 1
    tendon_zero_offsets_mm: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)

    @property
    def effect_terms(self) -> EffectTerms:
        return combined_terms(self.effects)

    @classmethod
    def from_toml(cls, path: str | Path = DEFAULT_PLANT_TOML) -> "PlantConfig":
        path = Path(path)
        try:
            raw = tomllib.loads(path.read_text())
            params = CatheterParams.from_toml(path.parent / raw.get("catheter", "catheter.toml"))
            params = params.replace(**{name: getattr(params, name) * _factor(name, factor)
                                       for name, factor in raw.get("mismatch", {}).items()})
            params = params.replace(**_dynamics(raw.get("dynamics", {})))
            tracker = raw.get("tracker", {})
            zeros = tuple(float(v) for v in raw.get("tendon_zero_offsets_mm", (0.0, 0.0, 0.0, 0.0)))
            if len(zeros) != 4:
                raise ValueError(f"tendon_zero_offsets_mm needs 4 values (mm), got {len(zeros)}")
            config = cls(params=params, n_elements=int(raw.get("n_elements", 20)),
                         effects={k: dict(v) for k, v in raw.get("effects", {}).items()},
                         tracker_noise_mm=float(tracker.get("noise_mm", 0.05)),
                         tracker_dropout=float(tracker.get("dropout", 0.0)),
                         tracker_seed=int(tracker.get("seed", 1)), tendon_zero_offsets_mm=zeros)
            config.effect_terms  # validates effect ids, names and ranges
        except (OSError, tomllib.TOMLDecodeError, ValueError, TypeError, AttributeError) as exc:
            raise PlantConfigError(f"{path}: {exc}") from exc
        if not 0.0 <= config.tracker_dropout < 1.0 or config.tracker_noise_mm < 0.0:
            raise PlantConfigError(f"{path}: [tracker] needs noise_mm >= 0 and 0 <= dropout < 1")
        return config

    def with_effects(self, effects: dict) -> "PlantConfig":
        """A copy with these effects switched on in addition ({id: {param: value}})."""
        merged = dict(self.effects)
        merged.update(effects)
        combined_terms(merged)
        return replace(self, effects=merged)


DYNAMICS_KEYS = ("damping_time_s", "inertia_scale")


def _dynamics(table) -> dict:
    """The [dynamics] table: the catheter's dampers and masses (CatheterParams), replacing catheter.toml's."""
    unknown = sorted(set(table) - set(DYNAMICS_KEYS))
    if unknown:
        raise ValueError(f"[dynamics] has unknown key(s) {unknown}; known: {list(DYNAMICS_KEYS)}")
    for name, value in table.items():
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ValueError(f"[dynamics].{name} must be a number, got {value!r}")
    return {name: float(value) for name, value in table.items()}


def _factor(name: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
        raise ValueError(f"[mismatch].{name} must be a positive factor, got {value!r}")
    return float(value)


class DahlPlant:
    """`model.DahlCatheter` behind the drives. No-argument construction reads configs/virtual_plant.toml."""

    def __init__(self, config: PlantConfig | None = None):
        self.config = config if config is not None else PlantConfig.from_toml()
        self.model = DahlCatheter(self.config.params, self.config.n_elements, self.config.effect_terms)

    def reset(self) -> None:
        self.model.reset()

    def step(self, dt_s: float, tendon_mm, insertion_mm: float) -> tuple[np.ndarray, np.ndarray]:
        """Advance to the drives' positions; returns (tip_mm (3,), tendon tension at the drives (4,)).

        The free length is held inside the catheter's [min, max] free length: the insertion drive's
        position is quantised to encoder counts, so at a soft limit equal to the catheter's maximum
        (100 mm) it reads up to a count beyond it, and the catheter cannot leave the tube further.
        """
        tendons = np.asarray(tendon_mm, dtype=float).reshape(1, 4) - np.asarray(self.config.tendon_zero_offsets_mm)
        params = self.config.params
        length_mm = min(max(float(insertion_mm), params.min_free_length_mm), params.max_free_length_mm)
        # a stalled bus can hand a long dt; the dynamic mode integrates at most MAX_DYNAMIC_SAMPLE_S of it
        dt_s = min(max(float(dt_s), 1e-6), MAX_DYNAMIC_SAMPLE_S)
        tip = self.model.run(tendons, np.array([length_mm]), dt_s=dt_s)[0]
        return tip, np.maximum(self.model.drive_tension_n, 0.0)
