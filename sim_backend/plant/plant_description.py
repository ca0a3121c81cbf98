"""Build the plant a plant description names: `family = "dahl"` (default) or `family = "rod"`.

A plant TOML (configs/virtual_plant.toml, configs/rod_plant.toml) says which family it
describes; each family reads its own parameters and effects, and both carry the same [tracker]
table (noise_mm, dropout, seed).
"""
from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path

from sim_backend.plant.plant_protocol import Plant

FAMILIES = ("dahl", "rod")


class PlantDescriptionError(ValueError):
    """The plant description cannot be read or names an unknown family."""


@dataclass(frozen=True)
class TrackerNoise:
    """The simulated tracker's noise, from the description's [tracker] table."""

    noise_mm: float
    dropout: float
    seed: int


def plant_family(path: str | Path) -> str:
    """The family a plant TOML describes ("dahl" when it has no `family` key)."""
    path = Path(path)
    try:
        family = tomllib.loads(path.read_text()).get("family", "dahl")
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise PlantDescriptionError(f"{path}: {exc}") from exc
    if family not in FAMILIES:
        raise PlantDescriptionError(f"{path}: family = {family!r}; known plant families: {', '.join(FAMILIES)}")
    return family


def load_plant_description(path: str | Path | None, effects: dict | None = None) -> tuple[Plant, TrackerNoise]:
    """(the plant, its tracker noise) from a plant TOML (default configs/virtual_plant.toml),
    with `effects` ({id: {param: value}}, in the family's own parameter names) switched on too."""
    effects = effects or {}
    if path is None:
        from sim_backend.plant.dahl_plant import DEFAULT_PLANT_TOML
        path = DEFAULT_PLANT_TOML
    if plant_family(path) == "rod":
        from sim_backend.plant.rod import RodDescription, RodPlant

        description = RodDescription.from_toml(path).with_effects(effects)
        return RodPlant(description), TrackerNoise(description.tracker_noise_mm, description.tracker_dropout,
                                                   description.tracker_seed)
    from sim_backend.plant.dahl_plant import DahlPlant, PlantConfig

    config = PlantConfig.from_toml(path).with_effects(effects)
    return DahlPlant(config), TrackerNoise(config.tracker_noise_mm, config.tracker_dropout, config.tracker_seed)


def plant_effect_ranges(family: str) -> dict:
    """{effect id: {"in_catalog", "physics", "params": {name: {low, typical, high, draw, allowed}}}}.

    draw: "log" (log-uniform in [low, high]), "log_signed" (magnitude log-uniform, sign at
    random) or "uniform". The Dahl family's ranges are the effect catalog's bounds, drawn uniformly.
    """
    if family == "rod":
        from sim_backend.plant.rod import effect_ranges

        return effect_ranges()
    if family == "dahl":
        from model.effects.catalog import EFFECTS

        return {e.id: {"in_catalog": True, "physics": e.physics,
                       "params": {name: {"low": lo, "typical": typ, "high": hi, "draw": "uniform",
                                         "allowed": [lo, hi]}
                                  for name, typ, lo, hi in zip(e.param_names, e.typical, e.lower, e.upper)}}
                for e in EFFECTS.values()}
    raise PlantDescriptionError(f"unknown plant family {family!r}; known plant families: {', '.join(FAMILIES)}")
