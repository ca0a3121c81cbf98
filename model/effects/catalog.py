"""The library of candidate unmodelled effects, under their canonical ids.

Each maps its parameters onto `EffectTerms` fields that the one model kernel computes.
"""
from __future__ import annotations

from collections.abc import Mapping

from model.effect_terms import EffectTerms
from model.effects.candidate_effect import CandidateEffect

EFFECTS: dict[str, CandidateEffect] = {e.id: e for e in (
    CandidateEffect(
        id="tendon_elasticity",
        physics="tendon and drive-line stretch under tension: the tip sees u - c*T_drive",
        param_names=("compliance_mm_per_n",), typical=(0.05,), lower=(0.0,), upper=(0.5,),
        signature="articulation lags the command in proportion to tension, at every articulation and most "
                  "over the shortest free lengths (a bend needs the most tension there); the calibrated base "
                  "model takes up the part that grows with tension, so adding it removes error in every region "
                  "of the motion and makes none worse, the shortest free lengths least of all",
        signature_region="every region",
        apply=lambda t, v: t.replace(tendon_compliance_mm_per_n=v[0])),
    CandidateEffect(
        id="backlash",
        physics="a dead band of width w in each tendon drive train, crossed at every reversal",
        param_names=("width_mm",), typical=(0.4,), lower=(0.0,), upper=(3.0,),
        signature="a flat dead band just after each reversal, independent of speed and load",
        signature_region="after reversal",
        apply=lambda t, v: t.replace(backlash_mm=v[0])),
    CandidateEffect(
        id="lumen_compression",
        physics="lumens pushed toward the neutral axis under load near the base: the moment arm shrinks",
        param_names=("coef_per_n", "extent_mm"), typical=(0.03, 20.0), lower=(0.0, 1.0), upper=(0.5, 200.0),
        signature="less bending than predicted at high articulation, growing with tension, near the base",
        signature_region="high articulation",
        apply=lambda t, v: t.replace(lumen_compression_per_n=v[0], lumen_compression_extent_mm=v[1])),
    CandidateEffect(
        id="tube_friction",
        physics="catheter/support-tube friction: the free length lags the insertion axis by a play",
        param_names=("play_mm",), typical=(2.0,), lower=(0.0,), upper=(10.0,),
        signature="error along the catheter after insertion reversals, tied to free-length changes",
        signature_region="",
        apply=lambda t, v: t.replace(tube_play_mm=v[0])),
    CandidateEffect(
        id="gravity",
        physics="sag under the catheter's own weight: element masses loaded by g across the insertion "
                "axis, which the testbed holds horizontal (g in the base x-y plane, g_z = 0)",
        param_names=("g_x_m_s2", "g_y_m_s2"), typical=(0.0, -9.81),
        # g acts on the prior's linear density, which nobody weighed: up to 5 g is a catheter five times
        # as heavy per mm as the bare shaft the prior describes (a fluid-filled lumen, a braid, a sensor cable)
        lower=(-50.0, -50.0), upper=(50.0, 50.0),
        signature="a fixed-direction offset that grows with free length, present at every articulation "
                  "(zero load included): adding it removes error in every region of the motion",
        signature_region="every region",
        apply=lambda t, v: t.replace(gravity_m_s2=(v[0], v[1], 0.0))),
    CandidateEffect(
        id="torsion",
        physics="twist of the lumens along the catheter: each bending plane couples into the other",
        param_names=("twist_rad",), typical=(0.25,), lower=(-1.0,), upper=(1.0,),
        signature="error out of the commanded bending plane, proportional to articulation",
        signature_region="high articulation",
        apply=lambda t, v: t.replace(twist_rad=v[0])),
    CandidateEffect(
        id="tracker_offset",
        physics="a rigid registration error of the tracker: a constant offset of the measured tip in the "
                "base frame",
        param_names=("dx_mm", "dy_mm", "dz_mm"), typical=(1.0, -0.8, 0.6),
        lower=(-10.0, -10.0, -10.0), upper=(10.0, 10.0, 10.0),
        signature="a constant bias everywhere: adding it removes error in every region of the motion",
        signature_region="every region",
        apply=lambda t, v: t.replace(tracker_offset_mm=(v[0], v[1], v[2]))),
    CandidateEffect(
        id="sensor_offset",
        physics="the tip sensor mounted off the tip centre: the tracker reports p_tip + R_tip d, with d "
                "fixed in the tip frame, so the offset turns with the tip",
        param_names=("dx_tip_mm", "dy_tip_mm", "dz_tip_mm"), typical=(1.0, -0.8, 0.6),
        lower=(-10.0, -10.0, -10.0), upper=(10.0, 10.0, 10.0),
        signature="an offset that turns with the tip, constant at zero load: adding it removes error in "
                  "every region of the motion",
        signature_region="every region",
        apply=lambda t, v: t.replace(sensor_offset_mm=(v[0], v[1], v[2]))),
    CandidateEffect(
        id="rate_friction",
        physics="velocity-strengthening tendon friction: Fs*(1 + c*|v|)",
        param_names=("coef_s_per_mm",), typical=(0.1,), lower=(0.0,), upper=(5.0,),
        signature="hysteresis loops that widen with speed; static holds agree",
        signature_region="fast",
        apply=lambda t, v: t.replace(rate_friction_s_per_mm=v[0])),
    CandidateEffect(
        id="precurvature",
        physics="residual rest curvature of the unactuated catheter",
        param_names=("kappa_x_per_mm", "kappa_y_per_mm"), typical=(0.002, -0.001),
        lower=(-0.02, -0.02), upper=(0.02, 0.02),
        signature="a bend in a fixed plane, scaling with free length, present at every articulation (zero "
                  "load included): adding it removes error in every region of the motion",
        signature_region="every region",
        apply=lambda t, v: t.replace(precurvature_per_mm=(v[0], v[1]))),
    CandidateEffect(
        id="rate_lag",
        physics="viscoelastic drive line (standard linear solid): a creep stretch s with s + tau*ds/dt = c*T_drive, "
                "so the catheter follows the drive with a first-order lag that grows with tension",
        param_names=("compliance_mm_per_n", "time_s"), typical=(0.05, 0.3), lower=(0.0, 0.01), upper=(0.5, 5.0),
        signature="the tip trails fast motion (error along the motion, growing with speed) and keeps creeping "
                  "without overshoot for ~tau after each stop; slow motion and settled holds agree; settled, it "
                  "stretches as an elastic line does, most over the shortest free lengths, so adding it makes "
                  "those no worse",
        signature_region="fast",
        apply=lambda t, v: t.replace(drive_creep_mm_per_n=v[0], drive_creep_time_s=v[1])),
)}


def effect(effect_id: str) -> CandidateEffect:
    """The candidate effect with this canonical id; a clear error lists the known ones."""
    try:
        return EFFECTS[effect_id]
    except KeyError:
        raise ValueError(f"unknown effect {effect_id!r}; known effects: {', '.join(EFFECTS)}") from None


def combined_terms(chosen: Mapping[str, Mapping[str, float] | tuple[float, ...]]) -> EffectTerms:
    """EffectTerms with every effect in `chosen` switched on ({id: {param: value}} or {id: values})."""
    terms = EffectTerms()
    for effect_id, values in chosen.items():
        candidate = effect(effect_id)
        if isinstance(values, Mapping):
            values = candidate.values_from(values)
        terms = candidate.terms(tuple(values), terms)
    return terms
