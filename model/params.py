"""Catheter parameters: immutable, validated, loadable from TOML.

`CatheterParams` is plain data: it can be loaded, validated, compared and replaced.
The model's state (element bends, friction forces) lives in `DahlCatheter`, never here.
Defaults are those in configs/catheter.toml (a 6 mm OD catheter, up to 100 mm free length).
"""
from __future__ import annotations

import dataclasses
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

from configs import CONFIG_DIR

DEFAULT_CATHETER_TOML = CONFIG_DIR / "catheter.toml"

# TOML table of each field: the file groups fields by topic.
_SECTIONS = {
    "geometry": ("outer_diameter_mm", "tendon_offset_mm", "free_length_mm", "min_free_length_mm",
                 "max_free_length_mm", "tendon_range_mm"),
    "stiffness": ("bending_stiffness_nmm2", "axial_stiffness_n", "tendon_stiffness_n",
                  "linear_density_kg_per_mm"),
    "friction": ("mu", "fsc_n_per_mm", "sigma_n_per_mm2", "alpha"),
    "dynamics": ("damping_time_s", "inertia_scale"),
}


class ParamsError(ValueError):
    """A catheter parameter is missing, not a finite number, or out of its physical range."""


@dataclass(frozen=True)
class CatheterParams:
    """Physical parameters of the catheter (units in the names).

    Per-element values follow from these so that results do not depend on the number of
    elements N (seed paper II.B, "invariant to the number of discrete elements"): with
    element length h = L/N, bending stiffness EI/h [N*mm/rad], axial stiffness EA/h [N/mm],
    Dahl stiffness sigma*h [N/mm], constant friction Fsc*h [N] and mass density*h [kg].

    Dynamics (seed paper I.A, Fig. 1; both 0 = the quasi-static model, the default):
    damping_time_s is the Kelvin-Voigt time tau = eta/EI of the bending dampers (per element
    c = tau*EI/h), inertia_scale scales the bend inertia that gives each element the first
    bending mode of a clamped-free beam of linear_density_kg_per_mm (per element
    m = scale * rho*L^4 / (12.362*h)); see model.quasi_static_kernel.dynamic_bend_offset.
    """

    outer_diameter_mm: float = 6.0
    tendon_offset_mm: float = 2.5
    free_length_mm: float = 80.0
    min_free_length_mm: float = 10.0
    max_free_length_mm: float = 100.0
    tendon_range_mm: tuple[float, float] = (-15.0, 15.0)
    bending_stiffness_nmm2: float = 900.0
    axial_stiffness_n: float = 100000.0
    tendon_stiffness_n: float = 50000.0
    linear_density_kg_per_mm: float = 4.0e-5
    mu: float = 0.2
    fsc_n_per_mm: float = 0.005
    sigma_n_per_mm2: float = 1.0
    alpha: float = 1.0
    damping_time_s: float = 0.0
    inertia_scale: float = 0.0

    def __post_init__(self) -> None:
        for field in dataclasses.fields(self):
            value = getattr(self, field.name)
            values = value if isinstance(value, tuple) else (value,)
            for v in values:
                if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                    raise ParamsError(f"catheter parameter '{field.name}' must be a finite number, got {value!r}")
        positive = ("outer_diameter_mm", "tendon_offset_mm", "free_length_mm", "min_free_length_mm",
                    "max_free_length_mm", "bending_stiffness_nmm2", "axial_stiffness_n",
                    "tendon_stiffness_n", "sigma_n_per_mm2", "alpha")
        for name in positive:
            if getattr(self, name) <= 0:
                raise ParamsError(f"catheter parameter '{name}' must be > 0, got {getattr(self, name)!r}")
        for name in ("mu", "fsc_n_per_mm", "linear_density_kg_per_mm", "damping_time_s", "inertia_scale"):
            if getattr(self, name) < 0:
                raise ParamsError(f"catheter parameter '{name}' must be >= 0, got {getattr(self, name)!r}")
        if self.tendon_offset_mm >= self.outer_diameter_mm / 2:
            raise ParamsError(f"catheter parameter 'tendon_offset_mm' ({self.tendon_offset_mm}) must be less than "
                              f"the outer radius ({self.outer_diameter_mm / 2})")
        if not self.min_free_length_mm <= self.free_length_mm <= self.max_free_length_mm:
            raise ParamsError(f"catheter parameter 'free_length_mm' ({self.free_length_mm}) must lie in "
                              f"[min_free_length_mm, max_free_length_mm] = "
                              f"[{self.min_free_length_mm}, {self.max_free_length_mm}]")
        if len(self.tendon_range_mm) != 2 or not self.tendon_range_mm[0] < self.tendon_range_mm[1]:
            raise ParamsError(f"catheter parameter 'tendon_range_mm' must be [min, max] with min < max, "
                              f"got {self.tendon_range_mm!r}")

    @property
    def dynamic(self) -> bool:
        """The dynamic mode is on exactly when the bends have damping or inertia."""
        return self.damping_time_s > 0 or self.inertia_scale > 0

    def replace(self, **changes) -> "CatheterParams":
        """A new, validated parameter set with `changes` applied; self is unchanged."""
        return dataclasses.replace(self, **changes)

    def frictionless(self) -> "CatheterParams":
        return self.replace(mu=0.0, fsc_n_per_mm=0.0)

    @classmethod
    def from_toml(cls, path: str | Path = DEFAULT_CATHETER_TOML) -> "CatheterParams":
        """Load parameters from a TOML file with [geometry], [stiffness], [friction] and [dynamics] tables.

        Keys may also sit at the top level. Missing keys keep their defaults; unknown keys
        and bad values raise ParamsError naming the file and the field.
        """
        path = Path(path)
        try:
            raw = tomllib.loads(path.read_text())
        except (OSError, tomllib.TOMLDecodeError) as exc:
            raise ParamsError(f"{path}: cannot read catheter parameters: {exc}") from exc
        flat: dict = {}
        known = {f.name for f in dataclasses.fields(cls)}
        for key, value in raw.items():
            if isinstance(value, dict):
                for sub_key, sub_value in value.items():
                    flat[sub_key] = sub_value
            else:
                flat[key] = value
        unknown = sorted(set(flat) - known)
        if unknown:
            raise ParamsError(f"{path}: unknown catheter parameter(s) {unknown}; known: {sorted(known)}")
        if "tendon_range_mm" in flat:
            flat["tendon_range_mm"] = tuple(flat["tendon_range_mm"])
        try:
            return cls(**flat)
        except ParamsError as exc:
            raise ParamsError(f"{path}: {exc}") from exc
        except TypeError as exc:
            raise ParamsError(f"{path}: {exc}") from exc

    def to_toml(self) -> str:
        """The parameters as TOML text, grouped like configs/catheter.toml."""
        lines = []
        for section, names in _SECTIONS.items():
            lines.append(f"[{section}]")
            for name in names:
                value = getattr(self, name)
                if isinstance(value, tuple):
                    lines.append(f"{name} = [{', '.join(repr(float(v)) for v in value)}]")
                else:
                    lines.append(f"{name} = {float(value)!r}")
            lines.append("")
        return "\n".join(lines)
