"""The fitted parameters: base model (stiffness, friction, tendon zeros) and candidate effects.

Each parameter has fit bounds (what least_squares may explore) and a narrower physical range
(what this catheter can plausibly have). A fit that ends at a bound or outside the physical
range is flagged: the model is bending that parameter to hide a missing effect.

Optimisation variables are dimensionless, about one per plausible change:
    z = ln(value / prior)   for stiffnesses (positive, spanning decades),
    z = value / scale       for the others.
Stiffness ranges are relative to the prior catheter (the starting parameters, e.g.
configs/catheter.toml), since the analysis knows no more about the catheter than that.
"""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from model.effects.catalog import effect
from model.params import CatheterParams

N_TENDONS = 4

@dataclass(frozen=True)
class FreeParameter:
    """One fitted scalar: name (units in it), fit bounds, physical range and its optimisation scaling."""

    name: str
    lower: float
    upper: float
    physical: tuple[float, float]
    log_reference: float | None = None   # z = ln(value / log_reference) when set
    scale: float = 1.0                    # z = value / scale otherwise

    def to_z(self, value: float) -> float:
        if self.log_reference is not None:
            return math.log(value / self.log_reference)
        return value / self.scale

    def from_z(self, z: float) -> float:
        if self.log_reference is not None:
            return self.log_reference * math.exp(z)
        return z * self.scale

    def std(self, z: float, std_z: float) -> float:
        """The standard deviation in physical units of one with std_z in z (one-sided for log scaling)."""
        if not np.isfinite(std_z) or (self.log_reference is not None and z + std_z > 700.0):
            return math.inf
        return abs(self.from_z(z + std_z) - self.from_z(z))

    def flag(self, value: float) -> str | None:
        """Why the fitted value is suspicious, or None (a bound counts when within 0.1 % of the z range)."""
        z, z_low, z_high = self.to_z(value), self.to_z(self.lower), self.to_z(self.upper)
        near = 1e-3 * (z_high - z_low)
        if z <= z_low + near and self.lower < self.physical[0]:
            return f"{self.name} = {value:.4g} ended at its lower fit bound {self.lower:.4g}"
        if z >= z_high - near:
            return f"{self.name} = {value:.4g} ended at its upper fit bound {self.upper:.4g}"
        low, high = self.physical
        if not low <= value <= high:
            return f"{self.name} = {value:.4g} left its physical range [{low:.4g}, {high:.4g}]"
        return None


TENDON_OFFSET_FIT_SPAN = 0.4       # the tendon offset is fitted within +-40 % of its nominal value
TENDON_OFFSET_PHYSICAL_SPAN = 0.2  # and is plausible within +-20 %


def tendon_offset_bounds_mm(nominal_mm: float, outer_diameter_mm: float, span: float) -> tuple[float, float]:
    """nominal * (1 -+ span), below 95 % of the outer radius (the lumens lie inside the shaft)."""
    return nominal_mm * (1.0 - span), min(nominal_mm * (1.0 + span), 0.95 * outer_diameter_mm / 2.0)


def base_parameters(prior: CatheterParams) -> tuple[FreeParameter, ...]:
    """Bending and axial stiffness, mu, sigma, Fsc, the tendon offset and the four tendon zero offsets.

    The tendon offset (the tendons' moment arm r) is fitted because no catheter's is known well:
    lumens sit off their drawn radius, tendons lie against one side of their lumen, and the
    real robot of ../shared/data bends as if its arm were 7-7.6 mm where its code says 8 or 4.
    The bend per mm of pull is about 1/r, so an arm 8 % off leaves a tip error that grows with
    articulation, and the other parameters leave their physical ranges trying to absorb it (the
    rod plant, r = 2.3 mm against a nominal 2.5: held-out 2.5 mm with mu at 0.68, 0.87 mm with
    the arm right).

    Tendon zeros are scaled by the tendon's own compliance L/EA_t (mm per N): with stiff
    tendons a zero error of a few micrometres changes the pretension by a newton and moves the
    tip by tenths of a millimetre, so one unit of z is one newton of pretension.

    Physical ranges: stiffnesses within x/÷10 (EI, sigma) or x/÷100 (EA, whose upper end is
    'incompressible') of the prior; mu of a tendon in a polymer lumen 0.02-0.6; Fsc up to
    0.05 N/mm (4 N over 80 mm); a tendon zero within +-1 mm of the drive's zero.
    Fit bounds are wider, except where the quasi-static solver stops converging or crawls:
    sigma above about 15x the default (stiff Dahl elements) and very high mu or Fsc.
    """
    ei, ea, sigma = prior.bending_stiffness_nmm2, prior.axial_stiffness_n, prior.sigma_n_per_mm2
    fsc_scale = max(prior.fsc_n_per_mm, 0.005)
    zero_scale = prior.max_free_length_mm / prior.tendon_stiffness_n
    r, diameter = prior.tendon_offset_mm, prior.outer_diameter_mm
    return (
        FreeParameter("bending_stiffness_nmm2", ei / 1000, ei * 1000, (ei / 10, ei * 10), log_reference=ei),
        FreeParameter("axial_stiffness_n", ea / 1e4, ea * 1e3, (ea / 100, ea * 100), log_reference=ea),
        FreeParameter("mu", 0.0, 1.0, (0.02, 0.6), scale=0.1),
        FreeParameter("sigma_n_per_mm2", sigma / 1000, sigma * 12, (sigma / 10, sigma * 10), log_reference=sigma),
        FreeParameter("fsc_n_per_mm", 0.0, 0.06, (0.0, 0.05), scale=fsc_scale),
        FreeParameter("tendon_offset_mm", *tendon_offset_bounds_mm(r, diameter, TENDON_OFFSET_FIT_SPAN),
                      tendon_offset_bounds_mm(r, diameter, TENDON_OFFSET_PHYSICAL_SPAN), scale=0.05 * r),
    ) + tuple(FreeParameter(f"tendon_zero_{k + 1}_mm", -3.0, 3.0, (-1.0, 1.0), scale=zero_scale)
              for k in range(N_TENDONS))


N_BASE = 10
BASE_NAMES = ("bending_stiffness_nmm2", "axial_stiffness_n", "mu", "sigma_n_per_mm2", "fsc_n_per_mm",
              "tendon_offset_mm") + tuple(f"tendon_zero_{k + 1}_mm" for k in range(N_TENDONS))


def base_values(params: CatheterParams, zero_offsets_mm: Sequence[float]) -> dict[str, float]:
    """The base parameters by name (BASE_NAMES order)."""
    values = [params.bending_stiffness_nmm2, params.axial_stiffness_n, params.mu, params.sigma_n_per_mm2,
              params.fsc_n_per_mm, params.tendon_offset_mm, *zero_offsets_mm]
    return dict(zip(BASE_NAMES, (float(v) for v in values)))


DYNAMIC_NAMES = ("damping_time_s", "inertia_scale")


def dynamic_parameters() -> tuple[FreeParameter, ...]:
    """The dynamic mode's damping time and inertia scale (CatheterParams [dynamics]), for fast logs.

    Physical ranges: a polymer shaft's Kelvin-Voigt time eta/EI up to 0.5 s; an inertia from 0 to 5
    times the catheter's own (a fluid-filled lumen, a sensor at the tip). Fit bounds 2 s and 20.
    """
    return (FreeParameter("damping_time_s", 0.0, 2.0, (0.0, 0.5), scale=0.02),
            FreeParameter("inertia_scale", 0.0, 20.0, (0.0, 5.0), scale=1.0))


def effect_parameters(effect_id: str) -> tuple[FreeParameter, ...]:
    """The candidate's parameters; its catalog range is both fit bound and physical range."""
    candidate = effect(effect_id)
    return tuple(FreeParameter(f"{effect_id}.{name}", low, high, (low, high), scale=(high - low) / 10)
                 for name, low, high in zip(candidate.param_names, candidate.lower, candidate.upper))


@dataclass(frozen=True)
class ParameterLayout:
    """The vector least_squares sees: the base parameters (if fitted), the dynamics (if fitted), then
    each effect's parameters."""

    prior: CatheterParams
    effect_ids: tuple[str, ...]
    fit_base: bool = True
    fit_dynamics: bool = False

    @property
    def parameters(self) -> tuple[FreeParameter, ...]:
        base = base_parameters(self.prior) if self.fit_base else ()
        base += dynamic_parameters() if self.fit_dynamics else ()
        return base + tuple(p for effect_id in self.effect_ids for p in effect_parameters(effect_id))

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parameters)

    def flags(self, values: Sequence[float]) -> tuple[str, ...]:
        """Why each fitted value (physical units, layout order) is suspicious (`FreeParameter.flag`)."""
        return tuple(flag for parameter, value in zip(self.parameters, values)
                     if (flag := parameter.flag(float(value))) is not None)

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        params = self.parameters
        return np.array([p.to_z(p.lower) for p in params]), np.array([p.to_z(p.upper) for p in params])

    def values(self, params: CatheterParams, zero_offsets_mm: Sequence[float],
               effects: Mapping[str, Sequence[float]]) -> np.ndarray:
        """Physical values in layout order."""
        base = list(base_values(params, zero_offsets_mm).values()) if self.fit_base else []
        base += [getattr(params, name) for name in DYNAMIC_NAMES] if self.fit_dynamics else []
        return np.array(base + [float(v) for effect_id in self.effect_ids for v in effects[effect_id]])

    def pack(self, params: CatheterParams, zero_offsets_mm: Sequence[float],
             effects: Mapping[str, Sequence[float]]) -> np.ndarray:
        """The optimisation vector z, clipped strictly inside the bounds."""
        values = self.values(params, zero_offsets_mm, effects)
        z = np.array([p.to_z(float(np.clip(v, p.lower, p.upper))) for p, v in zip(self.parameters, values)])
        low, high = self.bounds()
        inset = 1e-9 * np.maximum(1.0, high - low)
        return np.clip(z, low + inset, high - inset)

    def unpack(self, z: np.ndarray, params: CatheterParams, zero_offsets_mm: Sequence[float]
               ) -> tuple[CatheterParams, np.ndarray, dict[str, tuple[float, ...]]]:
        """(catheter params, zero offsets [4] mm, {effect id: values}) from z; fixed parts from the arguments."""
        values = [p.from_z(float(v)) for p, v in zip(self.parameters, z)]
        if self.fit_base:
            ei, ea, mu, sigma, fsc, offset = values[:6]
            params = params.replace(bending_stiffness_nmm2=ei, axial_stiffness_n=ea, mu=max(mu, 0.0),
                                    sigma_n_per_mm2=sigma, fsc_n_per_mm=max(fsc, 0.0), tendon_offset_mm=offset)
            zero_offsets_mm = values[6:N_BASE]
            values = values[N_BASE:]
        if self.fit_dynamics:
            params = params.replace(**{name: max(v, 0.0) for name, v in zip(DYNAMIC_NAMES, values)})
            values = values[len(DYNAMIC_NAMES):]
        effects = {}
        for effect_id in self.effect_ids:
            n = len(effect(effect_id).param_names)
            effects[effect_id], values = tuple(values[:n]), values[n:]
        return params, np.array(zero_offsets_mm, dtype=float), effects
