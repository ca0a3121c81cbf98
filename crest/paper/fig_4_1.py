"""Fig. 4.1: articulation to 270 deg at constant length for a sweep of friction coefficients (paper IV).

A larger mu consumes more tension per unit of wrap (capstan law, paper eq. 2-3), so the base
bends first and more: the tip swings wider ("a larger trajectory", measured by path length
and by its farthest reach from the insertion axis) and stops farther from the
constant-curvature end point.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from crest.paper.figure_output import CC_STYLE, new_figure, save_png, support_tube_patch, sweep_colors
from crest.paper.input_paths import articulation_ramp_mm
from crest.paper.settings import PaperSettings
from model import ConstantCurvature, DahlCatheter

FIGURE = "fig_4_1.png"
TITLE = "Fig. 4.1 articulation to 270 deg"
ARTICULATION_DEG = 270.0


def trajectory_numbers(tips_mm: np.ndarray, start_mm: np.ndarray) -> dict:
    """Size of a tip path: length [mm], farthest reach from the insertion axis [mm], lowest z [mm]."""
    path = np.vstack([start_mm, tips_mm])
    return {"path_length_mm": float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum()),
            "max_reach_from_axis_mm": float(np.hypot(path[:, 0], path[:, 1]).max()),
            "lowest_z_mm": float(path[:, 2].min())}


def run(settings: PaperSettings, out_dir: Path) -> dict:
    """For each mu of the sweep, articulate from straight to 270 deg at the configured length."""
    params = settings.params
    tendons = articulation_ramp_mm(params, 0.0, ARTICULATION_DEG, settings.step_deg)
    length_mm = params.free_length_mm
    start = np.array([0.0, 0.0, length_mm])
    cc = ConstantCurvature(params)
    cc_tips = np.array([cc.tip_mm(u, length_mm) for u in tendons])

    figure = new_figure(7.5, 7.0)
    ax = figure.subplots()
    ax.add_patch(support_tube_patch(params.outer_diameter_mm))
    cc_path = np.vstack([start, cc_tips])
    ax.plot(cc_path[:, 0], cc_path[:, 2], label="constant curvature", **CC_STYLE)
    ax.plot(*cc_tips[-1, [0, 2]], marker="*", markersize=14, color=CC_STYLE["color"], linestyle="none",
            label="constant-curvature end point")
    per_mu = []
    for mu, color in zip(settings.mu_sweep, sweep_colors(len(settings.mu_sweep))):
        tips = DahlCatheter(params.replace(mu=mu), settings.n_elements).run(tendons)
        path = np.vstack([start, tips])
        ax.plot(path[:, 0], path[:, 2], color=color, linewidth=1.8, label=f"mu = {mu:g}")
        ax.plot(*tips[-1, [0, 2]], marker="o", color=color)
        per_mu.append({"mu": mu, "end_tip_mm": tips[-1],
                       "end_distance_from_cc_end_mm": float(np.linalg.norm(tips[-1] - cc_tips[-1])),
                       **trajectory_numbers(tips, start)})
    ax.set(xlabel="x (toward tendon 1) [mm]", ylabel="z (insertion axis) [mm]", aspect="equal",
           title=f"{TITLE} at constant length {length_mm:g} mm (Fsc = {params.fsc_n_per_mm:g} N/mm)")
    ax.legend(fontsize=8, loc="upper right")
    ax.grid(alpha=0.3)
    save_png(figure, out_dir / FIGURE)

    return {"figure": FIGURE, "articulation_deg": ARTICULATION_DEG, "free_length_mm": length_mm,
            "constant_curvature": {"end_tip_mm": cc_tips[-1], **trajectory_numbers(cc_tips, start)},
            "per_mu": per_mu}
