"""Blind effect magnitudes: each parameter drawn from a range table, reaching down to the noise floor.

A range table is {effect id: {"in_catalog": bool, "params": {name: {"low", "typical", "high",
"draw"}}}} (the rod family's comes from its plant, `crest.backend.plant_effect_ranges`; the dahl
family's is DAHL_EFFECT_RANGES, in the effect catalog's parameters). Per parameter:

    log          log-uniform in [low, high]:  v = low (high/low)^U,  U ~ U(0, 1)
    log_signed   the same magnitude, sign + or - with probability 1/2
    uniform      uniform in [low, high]

Log-uniform magnitudes give every decade of size as many cases: the lower end moves the tip by
less than the tracker noise (0.05-0.2 mm per axis), so the benchmark measures where detection
starts (the detection-limit curve), not only how well a clearly present effect is named.
"""
from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np


def _log(low: float, high: float) -> dict:
    return {"low": low, "high": high, "draw": "log"}


def _signed(low: float, high: float) -> dict:
    return {"low": low, "high": high, "draw": "log_signed"}


# The Dahl plant's effects in the catalog's parameters (model/effects/catalog.py): from about
# 1/20 of the catalog's typical value (below the tracker noise on the short excitation) to 1.5x.
DAHL_EFFECT_RANGES: dict[str, dict] = {effect_id: {"in_catalog": True, "params": params} for effect_id, params in {
    "tendon_elasticity": {"compliance_mm_per_n": _log(0.003, 0.08)},
    "backlash": {"width_mm": _log(0.02, 0.6)},
    "lumen_compression": {"coef_per_n": _log(0.002, 0.045), "extent_mm": {"low": 10.0, "high": 40.0,
                                                                           "draw": "uniform"}},
    "tube_friction": {"play_mm": _log(0.1, 3.0)},
    "gravity": {"g_x_m_s2": _signed(0.3, 14.0), "g_y_m_s2": _signed(0.3, 14.0)},
    "torsion": {"twist_rad": _signed(0.015, 0.375)},
    "tracker_offset": {"dx_mm": _signed(0.03, 1.5), "dy_mm": _signed(0.03, 1.5), "dz_mm": _signed(0.03, 1.5)},
    "sensor_offset": {"dx_tip_mm": _signed(0.03, 1.5), "dy_tip_mm": _signed(0.03, 1.5),
                      "dz_tip_mm": _signed(0.03, 1.5)},
    "rate_friction": {"coef_s_per_mm": _log(0.006, 0.15)},
    "precurvature": {"kappa_x_per_mm": _signed(1e-4, 2.5e-3), "kappa_y_per_mm": _signed(1e-4, 2.5e-3)},
    "rate_lag": {"compliance_mm_per_n": _log(0.003, 0.08), "time_s": _log(0.05, 1.0)},
}.items()}


def draw_parameter(spec: Mapping, rng: np.random.Generator) -> float:
    """One parameter value from its range (see module doc)."""
    low, high, how = float(spec["low"]), float(spec["high"]), spec["draw"]
    if how == "uniform":
        return float(rng.uniform(low, high))
    if how not in ("log", "log_signed") or not 0.0 < low <= high:
        raise ValueError(f"range {dict(spec)}: draw must be log, log_signed or uniform, with 0 < low <= high "
                         "for the log draws")
    value = math.exp(rng.uniform(math.log(low), math.log(high)))
    return float(value * rng.choice([-1.0, 1.0])) if how == "log_signed" else float(value)


def draw_effect(ranges: Mapping[str, dict], effect_id: str, rng: np.random.Generator) -> dict[str, float]:
    """{parameter: value} of the effect, every parameter drawn from its range."""
    if effect_id not in ranges:
        raise ValueError(f"no drawing range for effect {effect_id!r}; the table has {', '.join(ranges)}")
    return {name: draw_parameter(spec, rng) for name, spec in ranges[effect_id]["params"].items()}


def catalog_ids(ranges: Mapping[str, dict]) -> list[str]:
    """The table's effects that the effect catalog has (the others exist only in the plant)."""
    return [effect_id for effect_id, spec in ranges.items() if spec["in_catalog"]]


def out_of_catalog_ids(ranges: Mapping[str, dict]) -> list[str]:
    """The table's effects that only the plant has."""
    return [effect_id for effect_id, spec in ranges.items() if not spec["in_catalog"]]
