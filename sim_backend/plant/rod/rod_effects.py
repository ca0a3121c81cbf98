"""The rod plant's effects, in its own physical terms, and the ranges a benchmark draws them from.

The ids are the effect catalog's (so a diagnosis can be scored against them) plus four that
exist only in this plant (sheath_creep, sheath_compression, lumen_offset_drift, stiffness_step).
The physics and the parameter names are this plant's own; rod_plant.py and step_solver.py
implement them.

Each parameter has an allowed interval (validation) and a drawing range (low, typical, high):
draw = "log": log-uniform in [low, high]; "log_signed": magnitude log-uniform in [low, high],
sign at random; "uniform": uniform in [low, high]. `typical` is what an omitted parameter takes
and moves the tip of a 80-100 mm catheter bent 120-180 deg by a few mm.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass


@dataclass(frozen=True)
class ParamRange:
    typical: float
    low: float
    high: float
    draw: str                    # "log", "log_signed" or "uniform"
    allowed: tuple[float, float]  # what validation accepts

    def as_dict(self) -> dict:
        return {"low": self.low, "typical": self.typical, "high": self.high, "draw": self.draw,
                "allowed": list(self.allowed)}


@dataclass(frozen=True)
class RodEffect:
    id: str
    physics: str
    params: Mapping[str, ParamRange]
    in_catalog: bool = True


def _p(typical, low, high, draw, allowed) -> ParamRange:
    return ParamRange(float(typical), float(low), float(high), draw, (float(allowed[0]), float(allowed[1])))


ROD_EFFECTS: dict[str, RodEffect] = {e.id: e for e in (
    RodEffect("tendon_elasticity",
              "extra drive-line compliance (a longer or softer cable between drum and catheter): "
              "c_d += extra_compliance_mm_per_n",
              {"extra_compliance_mm_per_n": _p(0.05, 0.01, 0.3, "log", (0.0, 2.0))}),
    RodEffect("backlash",
              "play between motor and tendon drum, the drum held by its bearing friction inside it: "
              "the drum follows the motor only once the motor crosses the play",
              {"gear_play_mm": _p(0.4, 0.1, 2.0, "log", (0.0, 5.0))}),
    RodEffect("lumen_compression",
              "the lumens' wall yields under load over the proximal soft_wall_length_mm (the seed "
              "paper's Fig. 3.1: lumens displaced by high loading, less curvature near the base): each "
              "tendon's own tension T pushes its lumen toward the neutral axis, moment arm "
              "r^2 / (r + radial_compliance_mm_per_n T)",
              {"radial_compliance_mm_per_n": _p(0.04, 0.005, 0.1, "log", (0.0, 10.0)),
               "soft_wall_length_mm": _p(20.0, 5.0, 40.0, "log", (0.1, 500.0))}),
    RodEffect("tube_friction",
              "Coulomb friction of the catheter in its support tube, driven through a compliant "
              "proximal shaft: the free length moves only once the shaft force exceeds the grip, "
              "a play of +-grip_friction_n / shaft_stiffness_n_per_mm",
              {"grip_friction_n": _p(2.0, 0.3, 4.0, "log", (0.0, 50.0)),
               "shaft_stiffness_n_per_mm": _p(1.0, 0.7, 3.0, "log", (0.01, 1000.0))}),
    RodEffect("gravity",
              "distributed self-weight load_n_per_mm (a fluid-filled shaft with its sensor cable, ~2x "
              "the dry shaft's 4e-4) across the insertion axis, pointing at direction_deg in the base "
              "x-y plane (0 = +x, 270 = -y); taut tendons carry much of it, so the sag is below a bare rod's",
              {"load_n_per_mm": _p(8e-4, 2e-4, 2e-3, "log", (0.0, 0.02)),
               "direction_deg": _p(270.0, 0.0, 360.0, "uniform", (-360.0, 720.0))}),
    RodEffect("torsion",
              "helical lumen routing: each tendon's angle in the cross-section turns by "
              "helix_rad_per_mm along the shaft (from the tip, fixed to the material)",
              {"helix_rad_per_mm": _p(0.003, 0.0005, 0.012, "log_signed", (-0.05, 0.05))}),
    RodEffect("tracker_offset",
              "the tracker registered to the base with a translation error (registration_x, "
              "registration_y, registration_z) in the base frame: every measured tip is shifted alike",
              {"registration_x_mm": _p(1.0, 0.2, 3.0, "log_signed", (-10.0, 10.0)),
               "registration_y_mm": _p(-0.8, 0.2, 3.0, "log_signed", (-10.0, 10.0)),
               "registration_z_mm": _p(0.6, 0.2, 3.0, "log_signed", (-10.0, 10.0))}),
    RodEffect("sensor_offset",
              "the tracker's sensor coil mounted off the tip centre, at (sensor_x, sensor_y, sensor_z) "
              "in the tip's frame: it turns with the tip",
              {"sensor_x_mm": _p(1.0, 0.2, 3.0, "log_signed", (-10.0, 10.0)),
               "sensor_y_mm": _p(-0.8, 0.2, 3.0, "log_signed", (-10.0, 10.0)),
               "sensor_z_mm": _p(1.5, 0.2, 4.0, "log_signed", (-10.0, 10.0))}),
    RodEffect("rate_friction",
              "velocity-strengthening tendon friction: mu(v) = mu (1 + mu_rate_s_per_mm |v|), v the "
              "tendon's sliding speed at the catheter base (mm/s); drawn up to 0.3 s/mm (mu x2.5 at "
              "5 mm/s): beyond, the tendons lock and a sweep stops on the tension limit",
              {"mu_rate_s_per_mm": _p(0.1, 0.02, 0.3, "log", (0.0, 10.0))}),
    RodEffect("precurvature",
              "a set taken by the shaft: uniform rest curvature (rest_kappa_x, rest_kappa_y) in the "
              "body frame; the tendons were zeroed on the catheter resting in that shape",
              {"rest_kappa_x_per_mm": _p(0.0015, 2e-4, 8e-3, "log_signed", (-0.03, 0.03)),
               "rest_kappa_y_per_mm": _p(-0.001, 2e-4, 8e-3, "log_signed", (-0.03, 0.03))}),
    RodEffect("sheath_creep",
              "viscoelastic creep of the sheath: its rest curvature relaxes toward creep_fraction of "
              "the bend with time_constant_s, so a sustained bend slowly deepens (long-term EI*(1-f))",
              {"creep_fraction": _p(0.15, 0.03, 0.3, "log", (0.0, 0.9)),
               "time_constant_s": _p(5.0, 1.0, 60.0, "log", (0.01, 1e5))}, in_catalog=False),
    RodEffect("sheath_compression",
              "a soft proximal sheath section of length soft_length_mm with axial stiffness "
              "soft_axial_stiffness_n: the summed tendon tension compresses it and takes up every "
              "tendon's pull alike",
              {"soft_length_mm": _p(20.0, 5.0, 60.0, "log", (0.1, 500.0)),
               "soft_axial_stiffness_n": _p(1000.0, 300.0, 5000.0, "log", (10.0, 1e7))}, in_catalog=False),
    RodEffect("lumen_offset_drift",
              "the lumens' radius drifts linearly along the free length, by tip_offset_change_mm at "
              "the tip relative to the tube exit",
              {"tip_offset_change_mm": _p(-0.4, 0.1, 1.0, "log_signed", (-2.0, 2.0))}, in_catalog=False),
    RodEffect("stiffness_step",
              "a distal section of different bending stiffness: EI * stiffness_ratio over the last "
              "distance_from_tip_mm of the shaft",
              {"distance_from_tip_mm": _p(30.0, 10.0, 60.0, "log", (0.0, 1000.0)),
               "stiffness_ratio": _p(0.6, 0.4, 0.9, "log", (0.05, 20.0))}, in_catalog=False),
)}


class RodEffectError(ValueError):
    """An effect id, parameter name or value the rod plant does not accept."""


def resolve_effects(chosen: Mapping[str, Mapping[str, float]]) -> dict[str, dict[str, float]]:
    """{id: {param: value}} with omitted parameters at their typical values, validated.

    Errors name the id or parameter and list the valid ones.
    """
    resolved = {}
    for effect_id, values in chosen.items():
        if effect_id not in ROD_EFFECTS:
            raise RodEffectError(f"unknown rod-plant effect {effect_id!r}; rod effects: {', '.join(ROD_EFFECTS)}")
        effect = ROD_EFFECTS[effect_id]
        if not isinstance(values, Mapping):
            raise RodEffectError(f"effect {effect_id!r}: expected a table of parameters "
                                 f"({', '.join(effect.params)}), got {values!r}")
        unknown = set(values) - set(effect.params)
        if unknown:
            raise RodEffectError(f"effect {effect_id!r} has no parameter {', '.join(sorted(map(repr, unknown)))}; "
                                 f"its parameters: {', '.join(effect.params)}")
        params = {}
        for name, spec in effect.params.items():
            value = values.get(name, spec.typical)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise RodEffectError(f"effect {effect_id!r}: {name} must be a number, got {value!r}")
            lo, hi = spec.allowed
            if not lo <= value <= hi:
                raise RodEffectError(f"effect {effect_id!r}: {name} = {value} is outside [{lo:g}, {hi:g}]")
            params[name] = float(value)
        resolved[effect_id] = params
    return resolved


def effect_ranges() -> dict[str, dict]:
    """{id: {"in_catalog": bool, "physics": str, "params": {param: {low, typical, high, draw, allowed}}}}."""
    return {e.id: {"in_catalog": e.in_catalog, "physics": e.physics,
                   "params": {name: spec.as_dict() for name, spec in e.params.items()}}
            for e in ROD_EFFECTS.values()}
