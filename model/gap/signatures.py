"""Residual signatures: the patterns that point at an unmodelled effect.

With e = tip_model - tip_measured (mm) on held-out samples:
- rate dependence: the lag along the motion, e . v/|v| (v the model tip velocity; > 0: the
  measured tip trails the model), per speed bin, and its slope against tendon speed. The
  loop width error is twice the lag: a hysteresis loop that widens with speed is rate friction.
- dead band after reversals: the tendon travel after a reversal before the tip has moved
  DEAD_BAND_TIP_MM (at least 4 sigma of tracker noise), measured and modelled (medians; a tip
  that has not moved within DEAD_BAND_WINDOW_DEG of articulation counts as the window); an
  excess is backlash (play) that the model lacks.
- static-hold bias: mean e over static samples; at zero load (straight and static) it is a
  tracker offset, gravity sag or precurvature.
- out of plane: e_perp = e . (-sin phi, cos phi, 0) for articulations >= 15 deg, its share of
  the squared error and its correlation with articulation (torsion couples the planes).
- correlations of |e| with total tension, free length and articulation.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from model.gap.recording import Recording
from model.gap.sample_features import SampleFeatures, bend_deg, reversals

DEAD_BAND_TIP_MM = 0.2
DEAD_BAND_WINDOW_DEG = 30.0
ZERO_LOAD_DEG = 5.0
OUT_OF_PLANE_MIN_DEG = 15.0
SPEED_BINS_MM_S = ((0.05, 2.0), (2.0, 6.0), (6.0, np.inf))


def _corr(a: np.ndarray, b: np.ndarray) -> float | None:
    """Pearson correlation, None for fewer than 10 samples or a (nearly) constant variable."""
    if len(a) < 10 or np.std(a) < 1e-9 or np.std(b) < 1e-9:
        return None
    return float(np.corrcoef(a, b)[0, 1])


def signatures(features: SampleFeatures, errors_mm: np.ndarray, recordings: Sequence[Recording],
               model_tips_mm: Sequence[np.ndarray], zero_offsets_mm: Sequence[float],
               noise_mm: float | None) -> dict:
    """All signatures of the residual (see module doc) as a plain dict; None where the data cannot tell."""
    f = features
    e = np.asarray(errors_mm)
    size = np.linalg.norm(e, axis=1)
    lag = np.concatenate([_lag_along_motion(tips, r) for r, tips in zip(recordings, model_tips_mm)])
    moving = np.isin(f.motion, ("loading", "unloading"))
    rate = {"speed_bins_mm_s": [], "loop_width_error_mm": [], "samples": []}
    for low, high in SPEED_BINS_MM_S:
        mask = moving & (f.speed_mm_s >= low) & (f.speed_mm_s < high)
        if mask.sum() >= 10:
            rate["speed_bins_mm_s"].append([low, high if np.isfinite(high) else None])
            rate["loop_width_error_mm"].append(float(2 * lag[mask].mean()))
            rate["samples"].append(int(mask.sum()))
    rate["slope_mm_per_mm_s"] = float(2 * np.polyfit(f.speed_mm_s[moving], lag[moving], 1)[0]) \
        if moving.sum() >= 10 and np.ptp(f.speed_mm_s[moving]) > 0 else None

    static = f.motion == "static"
    zero_load = static & (f.articulation_deg < ZERO_LOAD_DEG)
    bent = f.articulation_deg >= OUT_OF_PLANE_MIN_DEG
    phi = np.radians(f.plane_deg[bent])
    perp = e[bent, 0] * -np.sin(phi) + e[bent, 1] * np.cos(phi)
    return {
        "noise_mm": noise_mm,
        "rate_dependence": rate,
        "dead_band": _dead_band(recordings, model_tips_mm, zero_offsets_mm, noise_mm),
        "static_hold": _bias(e[static]),
        "zero_load": {**_bias(e[zero_load]),
                      "corr_free_length": _corr(size[zero_load], f.insertion_mm[zero_load])},
        "out_of_plane": {"rmse_mm": float(np.sqrt(np.mean(perp ** 2))) if bent.any() else None,
                         "share": float(np.sum(perp ** 2) / np.sum(e[bent] ** 2)) if bent.any() else None,
                         "corr_articulation": _corr(perp, f.articulation_deg[bent])},
        "correlations": {"total_tension": _corr(size, f.tension_n), "free_length": _corr(size, f.insertion_mm),
                         "articulation": _corr(size, f.articulation_deg)},
    }


def _bias(e: np.ndarray) -> dict:
    if len(e) < 3:
        return {"samples": int(len(e)), "mean_mm": None, "bias_mm": None, "rmse_mm": None}
    mean = e.mean(axis=0)
    return {"samples": int(len(e)), "mean_mm": [float(v) for v in mean], "bias_mm": float(np.linalg.norm(mean)),
            "rmse_mm": float(np.sqrt(np.mean(np.sum(e ** 2, axis=1))))}


def _lag_along_motion(model_tips: np.ndarray, recording: Recording) -> np.ndarray:
    """e . v/|v| on the valid samples (0 where the model tip does not move)."""
    velocity = np.gradient(model_tips, recording.t_s, axis=0)
    speed = np.linalg.norm(velocity, axis=1, keepdims=True)
    direction = np.divide(velocity, speed, out=np.zeros_like(velocity), where=speed > 1e-9)
    e = model_tips - recording.tip_mm
    return np.sum(e * direction, axis=1)[recording.valid]


def _dead_band(recordings: Sequence[Recording], model_tips_mm: Sequence[np.ndarray],
               zero_offsets_mm: Sequence[float], noise_mm: float | None) -> dict:
    """Median tendon travel (mm) after reversals before the tip moves, measured and modelled."""
    threshold = max(DEAD_BAND_TIP_MM, 4 * (noise_mm or 0.0))
    measured, modelled = [], []
    for r, tips in zip(recordings, model_tips_mm):
        bend = bend_deg(r, zero_offsets_mm)
        travel_mm = r.tendon_offset_mm * np.radians(1.0)   # tendon mm per degree of articulation
        for start in reversals(bend, r.t_s):
            origin = start - 1
            distance = np.hypot(*(bend[origin:] - bend[origin]).T)
            beyond = np.flatnonzero(distance > DEAD_BAND_WINDOW_DEG)
            window = np.arange(origin, origin + (beyond[0] if len(beyond) else len(distance)))
            travel = distance[: len(window)] * travel_mm
            for tips_source, out in ((r.tip_mm, measured), (tips, modelled)):
                if not np.isfinite(tips_source[origin]).all():
                    continue
                moved = np.linalg.norm(tips_source[window] - tips_source[origin], axis=1)
                crossed = np.flatnonzero(moved > threshold)
                if not len(crossed):
                    out.append(float(travel[-1]))
                elif crossed[0] > 0 and np.isfinite(moved[crossed[0] - 1]):
                    k = crossed[0]
                    w = (threshold - moved[k - 1]) / (moved[k] - moved[k - 1])
                    out.append(float(travel[k - 1] + w * (travel[k] - travel[k - 1])))
    if not measured or not modelled:
        return {"reversals": len(measured), "measured_mm": None, "model_mm": None, "excess_mm": None}
    return {"reversals": len(measured), "measured_mm": float(np.median(measured)),
            "model_mm": float(np.median(modelled)),
            "excess_mm": float(np.median(measured) - np.median(modelled))}


def describe(signature: dict, where: Sequence[dict], holdout_rmse_mm: float) -> list[str]:
    """Sentences on the residual's signature, e.g. for a gap no candidate explains."""
    lines = []
    noise = signature.get("noise_mm")
    if noise is not None:
        floor = float(np.sqrt(3) * noise)
        ratio = f" ({holdout_rmse_mm / floor:.1f}x)" if floor > 0 else " (no sample-to-sample noise: held samples)"
        lines.append(f"held-out RMSE {holdout_rmse_mm:.3f} mm against a tracker noise floor of {floor:.3f} mm"
                     + ratio)
    for row in where[:3]:
        if row["concentration"] >= 1.5:
            lines.append(f"concentrated in {row['region']} ({row['concentration']:.1f}x its share of samples, "
                         f"{row['rmse_mm']:.3f} mm RMS)")
    rate = signature["rate_dependence"]
    if rate.get("slope_mm_per_mm_s") is not None and abs(rate["slope_mm_per_mm_s"]) > 0.02:
        lines.append(f"loop width error changes by {rate['slope_mm_per_mm_s']:+.3f} mm per mm/s of tendon speed")
    band = signature["dead_band"]
    if band.get("excess_mm") is not None and abs(band["excess_mm"]) > 0.05:
        lines.append(f"dead band after reversals {band['measured_mm']:.2f} mm of tendon travel measured vs "
                     f"{band['model_mm']:.2f} mm modelled")
    zero = signature["zero_load"]
    if zero.get("bias_mm") is not None and zero["bias_mm"] > 0.1:
        lines.append(f"bias at zero load {zero['bias_mm']:.3f} mm")
    plane = signature["out_of_plane"]
    if plane.get("share") is not None and plane["share"] > 0.5:
        lines.append(f"{100 * plane['share']:.0f} % of the error is out of the bending plane")
    return lines
