"""Fig. 3.2: tip trajectory on the way to 180 deg articulation, constant curvature vs friction (paper III).

The paper's headline compares both models with its prototype at 180 deg: 0.31 cm tip error
with friction against more than 1 cm with constant curvature. Without prototype data we
report how far the friction model's tip lies from the constant-curvature tip, for the same
tendon input, at 180 deg and along the path.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from crest.paper.figure_output import (CC_STYLE, FRICTION_STYLE, FRICTIONLESS_STYLE, new_figure, save_png,
                                      support_tube_patch)
from crest.paper.input_paths import articulation_ramp_mm
from crest.paper.settings import PaperSettings
from model import ConstantCurvature, DahlCatheter

FIGURE = "fig_3_2.png"
TITLE = "Fig. 3.2 tip trajectory to 180 deg"
ARTICULATION_DEG = 180.0


def run(settings: PaperSettings, out_dir: Path) -> dict:
    """Articulate from straight to 180 deg; returns end points and path deviations."""
    params = settings.params
    tendons = articulation_ramp_mm(params, 0.0, ARTICULATION_DEG, settings.step_deg)
    length_mm = params.free_length_mm
    cc = ConstantCurvature(params)
    cc_tips = np.array([cc.tip_mm(u, length_mm) for u in tendons])
    friction = DahlCatheter(params, settings.n_elements)
    frictionless = DahlCatheter(params.frictionless(), settings.n_elements)
    friction_tips = friction.run(tendons)
    frictionless_tips = frictionless.run(tendons)
    end_difference_mm = float(np.linalg.norm(friction_tips[-1] - cc_tips[-1]))

    figure = new_figure(7.5, 6.5)
    ax = figure.subplots()
    ax.add_patch(support_tube_patch(params.outer_diameter_mm))
    start = np.array([[0.0, 0.0, length_mm]])
    for tips, style, label in ((cc_tips, CC_STYLE, "constant curvature"),
                               (frictionless_tips, FRICTIONLESS_STYLE, "lumped model, no friction"),
                               (friction_tips, FRICTION_STYLE, f"lumped model with friction (mu = {params.mu:g})")):
        path = np.vstack([start, tips])
        ax.plot(path[:, 0], path[:, 2], label=label, **style)
        ax.plot(path[-1, 0], path[-1, 2], marker="o", color=style["color"])
    shape = friction.backbone_mm
    ax.plot(shape[:, 0], shape[:, 2], color=FRICTION_STYLE["color"], alpha=0.35, linewidth=4,
            label="shape with friction at 180 deg")
    cc_shape = cc.backbone_mm(tendons[-1], length_mm, n_points=41)
    ax.plot(cc_shape[:, 0], cc_shape[:, 2], color="0.35", alpha=0.3, linewidth=4,
            label="constant-curvature shape at 180 deg")
    ax.annotate(f"{end_difference_mm:.1f} mm", xy=friction_tips[-1, [0, 2]], xytext=(12, -4),
                textcoords="offset points", color=FRICTION_STYLE["color"])
    ax.set(xlabel="x (toward tendon 1) [mm]", ylabel="z (insertion axis) [mm]", aspect="equal",
           title=f"{TITLE}: end point {end_difference_mm:.1f} mm from constant curvature")
    ax.legend(loc="upper right", fontsize=8)
    ax.grid(alpha=0.3)
    save_png(figure, out_dir / FIGURE)

    return {
        "figure": FIGURE,
        "articulation_deg": ARTICULATION_DEG,
        "end_tip_mm": {"constant_curvature": cc_tips[-1], "frictionless": frictionless_tips[-1],
                       "friction": friction_tips[-1]},
        "end_difference_cc_vs_friction_mm": end_difference_mm,
        "end_difference_cc_vs_frictionless_mm": float(np.linalg.norm(frictionless_tips[-1] - cc_tips[-1])),
        "max_path_difference_cc_vs_friction_mm": float(np.linalg.norm(friction_tips - cc_tips, axis=1).max()),
    }
