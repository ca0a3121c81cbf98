"""What the rod plant's catheter is: shaft, tendons, friction, grid, effects, tracker noise.

Read from a plant TOML with family = "rod" (configs/rod_plant.toml documents every key).
Unknown tables or keys are errors, so a misspelt parameter never silently takes a default.
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path

from sim_backend.plant.rod.rod_effects import RodEffectError, resolve_effects

DEFAULT_ROD_TOML = Path(__file__).resolve().parents[3] / "configs" / "rod_plant.toml"


class RodDescriptionError(ValueError):
    """The rod plant's description is invalid; the message names the file and the field."""


# TOML table -> {key: RodDescription field}
_LAYOUT = {
    "shaft": {"youngs_modulus_mpa": "youngs_modulus_mpa", "outer_diameter_mm": "outer_diameter_mm",
              "inner_diameter_mm": "inner_diameter_mm", "axial_stiffness_n": "axial_stiffness_n",
              "grid_nodes": "grid_nodes", "damping_time_s": "damping_time_s"},
    "tendons": {"offset_mm": "tendon_offset_mm", "axial_stiffness_n": "tendon_axial_stiffness_n",
                "drive_compliance_mm_per_n": "drive_compliance_mm_per_n",
                "zero_offsets_mm": "tendon_zero_offsets_mm"},
    "friction": {"mu": "mu", "constant_n_per_mm": "friction_n_per_mm"},
    "tracker": {"noise_mm": "tracker_noise_mm", "dropout": "tracker_dropout", "seed": "tracker_seed"},
}


@dataclass(frozen=True)
class RodDescription:
    """The rod plant's parameters, in its own terms (units in the names).

    bending stiffness EI = E * pi/64 * (D^4 - d^4) (E in MPa = N/mm^2, so EI in N*mm^2).
    """

    youngs_modulus_mpa: float = 13.5
    outer_diameter_mm: float = 6.0
    inner_diameter_mm: float = 3.0
    axial_stiffness_n: float = 1.0e5           # EA of the shaft
    grid_nodes: int = 200                       # nodes over the free length
    damping_time_s: float = 0.0                 # Kelvin-Voigt retardation time eta/E of the shaft (0: quasi-static)
    tendon_offset_mm: float = 2.3               # radius of the tendon lumens from the neutral axis
    tendon_axial_stiffness_n: float = 4.0e4     # EA_t of a tendon
    drive_compliance_mm_per_n: float = 0.01     # drive line outside the catheter, mm of stretch per N
    tendon_zero_offsets_mm: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    mu: float = 0.23                            # tendon/lumen Coulomb friction coefficient
    friction_n_per_mm: float = 0.006            # constant (interference) friction per mm of lumen
    effects: dict = field(default_factory=dict)   # {effect id: {param: value}}, resolved
    tracker_noise_mm: float = 0.05
    tracker_dropout: float = 0.0
    tracker_seed: int = 1

    def __post_init__(self):
        self._check()

    @property
    def bending_stiffness_nmm2(self) -> float:
        return self.youngs_modulus_mpa * math.pi / 64.0 * (self.outer_diameter_mm ** 4 - self.inner_diameter_mm ** 4)

    @classmethod
    def from_toml(cls, path: str | Path = DEFAULT_ROD_TOML) -> "RodDescription":
        path = Path(path)
        try:
            raw = tomllib.loads(path.read_text())
        except (OSError, tomllib.TOMLDecodeError) as exc:
            raise RodDescriptionError(f"{path}: {exc}") from exc
        try:
            return cls(**_fields_from(raw))
        except (RodDescriptionError, RodEffectError) as exc:
            raise RodDescriptionError(f"{path}: {exc}") from exc

    def with_effects(self, effects: dict) -> "RodDescription":
        """A copy with these effects switched on in addition ({id: {param: value}})."""
        merged = dict(self.effects)
        merged.update(effects)
        return replace(self, effects=merged)

    def _check(self) -> None:
        positive = ("youngs_modulus_mpa", "outer_diameter_mm", "axial_stiffness_n", "tendon_offset_mm",
                    "tendon_axial_stiffness_n")
        non_negative = ("inner_diameter_mm", "drive_compliance_mm_per_n", "mu", "friction_n_per_mm",
                        "tracker_noise_mm", "damping_time_s")
        for name in positive + non_negative:
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise RodDescriptionError(f"{name} must be a number, got {value!r}")
            if value < 0 or (name in positive and value == 0):
                raise RodDescriptionError(f"{name} must be {'> 0' if name in positive else '>= 0'}, got {value}")
        if self.inner_diameter_mm >= self.outer_diameter_mm:
            raise RodDescriptionError(f"inner_diameter_mm ({self.inner_diameter_mm}) must be below "
                                      f"outer_diameter_mm ({self.outer_diameter_mm})")
        if self.tendon_offset_mm >= self.outer_diameter_mm / 2:
            raise RodDescriptionError(f"tendons.offset_mm ({self.tendon_offset_mm}) must lie inside the shaft "
                                      f"(< outer_diameter_mm / 2 = {self.outer_diameter_mm / 2})")
        if isinstance(self.grid_nodes, bool) or not isinstance(self.grid_nodes, int) or not 8 <= self.grid_nodes <= 5000:
            raise RodDescriptionError(f"shaft.grid_nodes must be an integer in [8, 5000], got {self.grid_nodes!r}")
        if len(self.tendon_zero_offsets_mm) != 4:
            raise RodDescriptionError(f"tendons.zero_offsets_mm needs 4 values (mm), got {len(self.tendon_zero_offsets_mm)}")
        if not 0.0 <= self.tracker_dropout < 1.0:
            raise RodDescriptionError(f"tracker.dropout must be in [0, 1), got {self.tracker_dropout}")
        object.__setattr__(self, "effects", resolve_effects(self.effects))
        drift = self.effects.get("lumen_offset_drift", {}).get("tip_offset_change_mm", 0.0)
        if not 0.0 < self.tendon_offset_mm + drift < self.outer_diameter_mm / 2:
            raise RodDescriptionError(f"effect 'lumen_offset_drift': tip_offset_change_mm = {drift} puts the tip "
                                      f"lumens at {self.tendon_offset_mm + drift} mm, outside (0, "
                                      f"{self.outer_diameter_mm / 2}) mm")


def _fields_from(raw: dict) -> dict:
    family = raw.get("family", "rod")
    if family != "rod":
        raise RodDescriptionError(f"family = {family!r}: this is not a rod plant description")
    known_tables = set(_LAYOUT) | {"effects"}
    values: dict = {}
    for key, table in raw.items():
        if key == "family":
            continue
        if key not in known_tables:
            raise RodDescriptionError(f"unknown key or table {key!r}; a rod description has family and the tables "
                                      f"{', '.join(sorted(known_tables))}")
        if not isinstance(table, dict):
            raise RodDescriptionError(f"[{key}] must be a table")
        if key == "effects":
            values["effects"] = {k: dict(v) if isinstance(v, dict) else v for k, v in table.items()}
            continue
        for name, value in table.items():
            if name not in _LAYOUT[key]:
                raise RodDescriptionError(f"[{key}] has no key {name!r}; its keys: {', '.join(_LAYOUT[key])}")
            values[_LAYOUT[key][name]] = value
    if "tendon_zero_offsets_mm" in values:
        zeros = values["tendon_zero_offsets_mm"]
        if not isinstance(zeros, list) or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in zeros):
            raise RodDescriptionError(f"tendons.zero_offsets_mm must be a list of 4 numbers (mm), got {zeros!r}")
        values["tendon_zero_offsets_mm"] = tuple(float(v) for v in zeros)
    for name in ("tracker_seed",):
        if name in values and (isinstance(values[name], bool) or not isinstance(values[name], int)):
            raise RodDescriptionError(f"tracker.seed must be an integer, got {values[name]!r}")
    return values
