"""Fig. 4.3: circles in a plane normal to the insertion axis at several articulation angles (paper IV).

The command keeps the articulation theta and turns the bending plane phi through all four
tendons, u_k = r theta cos(phi_k - phi); constant curvature then puts the tip on the circle of
radius R = L (1 - cos theta) / theta at height z_c = L sin theta / theta. The commanded
circle is compared with the second lap of the model (the first lap starts from the lead-in).

Measures, with rho = sqrt(x^2 + y^2) the tip's distance from the insertion axis and psi its
polar angle:
    distance to the commanded circle  d = sqrt((rho - R)^2 + (z - z_c)^2)
    radius ratio                       mean(rho) / R
    bulge toward the tendons           mean rho(psi) at psi = 0, 90, 180, 270 deg minus
                                       mean rho(psi) at psi = 45, 135, 225, 315 deg
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from crest.paper.figure_output import new_figure, save_png, sweep_colors
from crest.paper.input_paths import articulation_ramp_mm, plane_sweep_mm
from crest.paper.settings import PaperSettings
from model import ConstantCurvature, DahlCatheter

FIGURE = "fig_4_3.png"
TITLE = "Fig. 4.3 circles normal to the insertion axis"
TENDON_ANGLES_DEG = np.array([0.0, 90.0, 180.0, 270.0])
BETWEEN_TENDONS_DEG = TENDON_ANGLES_DEG + 45.0
LAPS = 2


def radius_at_deg(tips_mm: np.ndarray, angles_deg: np.ndarray) -> np.ndarray:
    """Distance of the tip path from the insertion axis where its polar angle is angles_deg [mm]."""
    psi = np.mod(np.arctan2(tips_mm[:, 1], tips_mm[:, 0]), 2 * np.pi)
    rho = np.hypot(tips_mm[:, 0], tips_mm[:, 1])
    order = np.argsort(psi)
    return np.interp(np.deg2rad(angles_deg), psi[order], rho[order], period=2 * np.pi)


def circle_numbers(tips_mm: np.ndarray, cc_radius_mm: float, cc_height_mm: float) -> dict:
    """Deviation, size and bulges of one measured lap against the commanded circle."""
    rho = np.hypot(tips_mm[:, 0], tips_mm[:, 1])
    distance = np.hypot(rho - cc_radius_mm, tips_mm[:, 2] - cc_height_mm)
    at_tendons = radius_at_deg(tips_mm, TENDON_ANGLES_DEG)
    between = radius_at_deg(tips_mm, BETWEEN_TENDONS_DEG)
    return {"mean_distance_to_commanded_circle_mm": float(distance.mean()),
            "max_distance_to_commanded_circle_mm": float(distance.max()),
            "mean_radius_mm": float(rho.mean()),
            "radius_ratio_to_cc": float(rho.mean() / cc_radius_mm),
            "mean_height_mm": float(tips_mm[:, 2].mean()),
            "radius_at_tendon_angles_mm": at_tendons,
            "radius_between_tendons_mm": between,
            "bulge_toward_tendons_mm": float(at_tendons.mean() - between.mean()),
            "radial_deviation_at_tendons_mm": float(np.abs(at_tendons - cc_radius_mm).mean()),
            "radial_deviation_between_tendons_mm": float(np.abs(between - cc_radius_mm).mean())}


def run(settings: PaperSettings, out_dir: Path) -> dict:
    """For each articulation: lead in along tendon 1's plane, then turn the plane through LAPS laps."""
    params = settings.params
    length_mm = params.free_length_mm
    cc = ConstantCurvature(params)
    laps = []
    for theta_deg in settings.circle_articulations_deg:
        lead_in = articulation_ramp_mm(params, 0.0, theta_deg, settings.step_deg)
        planes_deg, circle = plane_sweep_mm(params, theta_deg, 0.0, 360.0 * LAPS, settings.step_deg)
        model = DahlCatheter(params, settings.n_elements)
        model.run(lead_in)
        tips = model.run(circle)[planes_deg > 360.0 * (LAPS - 1)]
        cc_tip = cc.tip_mm(lead_in[-1], length_mm)
        cc_radius_mm, cc_height_mm = float(np.hypot(cc_tip[0], cc_tip[1])), float(cc_tip[2])
        laps.append((theta_deg, tips, cc_radius_mm, cc_height_mm))

    _draw(settings, laps, out_dir / FIGURE)
    return {"figure": FIGURE, "laps_measured": 1, "tendon_angles_deg": TENDON_ANGLES_DEG,
            "between_tendons_deg": BETWEEN_TENDONS_DEG,
            "per_articulation": [{"articulation_deg": theta_deg, "cc_radius_mm": radius, "cc_height_mm": height,
                                  **circle_numbers(tips, radius, height)}
                                 for theta_deg, tips, radius, height in laps]}


def _draw(settings: PaperSettings, laps: list, path: Path) -> None:
    figure = new_figure(16.0, 5.6)
    side = figure.add_subplot(1, 3, 1)
    top = figure.add_subplot(1, 3, 2)
    oblique = figure.add_subplot(1, 3, 3, projection="3d")
    circle = np.linspace(0.0, 2 * np.pi, 181)
    colors = sweep_colors(len(laps))
    for (theta_deg, tips, radius, height), color in zip(laps, colors):
        label = f"{theta_deg:g} deg"
        closed = np.vstack([tips, tips[:1]])
        side.plot(closed[:, 0], closed[:, 2], color=color, linewidth=1.6, label=label)
        side.plot([-radius, radius], [height, height], color=color, linestyle="--", linewidth=1.0)
        top.plot(closed[:, 0], closed[:, 1], color=color, linewidth=1.6, label=label)
        top.plot(radius * np.cos(circle), radius * np.sin(circle), color=color, linestyle="--", linewidth=1.0)
        oblique.plot(closed[:, 0], closed[:, 1], closed[:, 2], color=color, linewidth=1.6, label=label)
    reach = max(radius for _, _, radius, _ in laps) * 1.15
    for angle_deg, name in zip(TENDON_ANGLES_DEG, ("tendon 1", "tendon 2", "tendon 3", "tendon 4")):
        direction = np.array([np.cos(np.deg2rad(angle_deg)), np.sin(np.deg2rad(angle_deg))])
        top.plot([0.0, reach * direction[0]], [0.0, reach * direction[1]], color="0.6", linewidth=0.8)
        top.annotate(name, reach * direction, ha="center", va="center", fontsize=8, color="0.3",
                     bbox={"facecolor": "white", "edgecolor": "none", "alpha": 0.8})
    side.set(xlabel="x (toward tendon 1) [mm]", ylabel="z (insertion axis) [mm]",
             title="(a) side view (dashed: commanded circles)")
    top.set(xlabel="x (toward tendon 1) [mm]", ylabel="y (toward tendon 2) [mm]", aspect="equal",
            title="(b) top view along the insertion axis")
    oblique.set(xlabel="x [mm]", ylabel="y [mm]", zlabel="z [mm]", title="(c) oblique view (model only)")
    oblique.view_init(elev=25.0, azim=-60.0)
    for ax in (side, top):
        ax.grid(alpha=0.3)
    side.legend(title="articulation", fontsize=8, title_fontsize=8)
    figure.suptitle(f"{TITLE}, friction model mu = {settings.params.mu:g} (solid) vs constant curvature (dashed)")
    save_png(figure, path)
