"""Fig. 4.2: insertion in and out at 180 deg articulation for a sweep of friction coefficients (paper IV).

Constant curvature keeps theta = (u1 - u3) / (2 r) whatever the free length L, so at 180 deg
its tip x = 2 L / pi, z = 0 runs along a horizontal line as L changes. With friction the
Dahl forces travel with the material (model.quasi_static_kernel.remap_to_length), catheter
that leaves the tube arrives unloaded, and the tendons re-slide as the same pull bends a
new length: the friction distribution, and with it the tip, moves off that line (vertically).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from crest.paper.figure_output import CC_STYLE, new_figure, save_png, sweep_colors
from crest.paper.input_paths import articulation_ramp_mm, insertion_cycle_mm
from crest.paper.settings import PaperSettings
from model import ConstantCurvature, DahlCatheter

FIGURE = "fig_4_2.png"
TITLE = "Fig. 4.2 insertion in and out at 180 deg"
ARTICULATION_DEG = 180.0
INSERTION_STEP_MM = 1.0


def insertion_waypoints_mm(free_length_mm: float, max_free_length_mm: float) -> tuple[float, ...]:
    """Out to the longest free length, in to 5/8 of the start length, back to the start."""
    return free_length_mm, max_free_length_mm, 0.625 * free_length_mm, free_length_mm


def run(settings: PaperSettings, out_dir: Path) -> dict:
    """For each mu: articulate to 180 deg at the configured length, then cycle the insertion."""
    params = settings.params
    articulation = articulation_ramp_mm(params, 0.0, ARTICULATION_DEG, settings.step_deg)
    waypoints = insertion_waypoints_mm(params.free_length_mm, params.max_free_length_mm)
    insertion = insertion_cycle_mm(waypoints, INSERTION_STEP_MM)
    tendons = np.tile(articulation[-1], (len(insertion), 1))
    cc = ConstantCurvature(params)
    cc_tips = np.array([cc.tip_mm(articulation[-1], length) for length in insertion])

    figure = new_figure(9.0, 6.0)
    ax = figure.subplots()
    ax.plot(cc_tips[:, 0], cc_tips[:, 2], label="constant curvature (horizontal line)", **CC_STYLE)
    per_mu = []
    for mu, color in zip(settings.mu_sweep, sweep_colors(len(settings.mu_sweep))):
        model = DahlCatheter(params.replace(mu=mu), settings.n_elements)
        start = model.run(articulation)[-1]
        tips = np.vstack([start, model.run(tendons, insertion)])
        ax.plot(tips[:, 0], tips[:, 2], color=color, linewidth=1.8, label=f"mu = {mu:g}")
        ax.plot(*start[[0, 2]], marker="o", color=color)
        vertical_mm = tips[:, 2] - np.concatenate([[cc_tips[-1, 2]], cc_tips[:, 2]])
        per_mu.append({"mu": mu, "start_tip_mm": start, "end_tip_mm": tips[-1],
                       "max_vertical_deviation_from_cc_line_mm": float(np.abs(vertical_mm).max()),
                       "vertical_deflection_span_mm": float(np.ptp(tips[:, 2])),
                       "max_distance_from_cc_mm": float(np.linalg.norm(tips[1:] - cc_tips, axis=1).max()),
                       "return_offset_mm": float(np.linalg.norm(tips[-1] - start))})
    ax.set(xlabel="x (radial, toward tendon 1) [mm]", ylabel="z (insertion axis) [mm]",
           title=f"{TITLE}: free length {' -> '.join(f'{w:g}' for w in waypoints)} mm")
    ax.legend(fontsize=8, title="dot: start after articulation", title_fontsize=8)
    ax.grid(alpha=0.3)
    save_png(figure, out_dir / FIGURE)

    return {"figure": FIGURE, "articulation_deg": ARTICULATION_DEG, "insertion_waypoints_mm": waypoints,
            "cc_line_max_abs_z_mm": float(np.abs(cc_tips[:, 2]).max()), "per_mu": per_mu}
