"""Fig. 3.1: catheter shape and radius of curvature along the arc at 90 deg (paper III).

Friction consumes tendon tension on its way from the drive to the tip (paper II.B: each more
proximal tension adds the Dahl forces distal to it), so while pulling, the bending moment
r * T(s) and with it the curvature kappa(s) = r T(s) / EI fall from the base to the tip.
Constant curvature has kappa = theta / L everywhere. The lumped model's curvature of element i
is |b_i| / h at arc length s_i = (i + 1/2) h from the support-tube exit.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from crest.paper.figure_output import (CC_STYLE, FRICTION_STYLE, FRICTIONLESS_STYLE, new_figure, save_png,
                                      support_tube_patch)
from crest.paper.input_paths import articulation_ramp_mm
from crest.paper.settings import PaperSettings
from model import ConstantCurvature, DahlCatheter, bend_from_tendons

FIGURE = "fig_3_1.png"
TITLE = "Fig. 3.1 shape and curvature at 90 deg"
ARTICULATION_DEG = 90.0


def run(settings: PaperSettings, out_dir: Path) -> dict:
    """Articulate to 90 deg from straight; returns the curvature profile and tip positions."""
    params = settings.params
    tendons = articulation_ramp_mm(params, 0.0, ARTICULATION_DEG, settings.step_deg)
    friction = DahlCatheter(params, settings.n_elements)
    frictionless = DahlCatheter(params.frictionless(), settings.n_elements)
    for model in (friction, frictionless):
        model.run(tendons)
    cc = ConstantCurvature(params)
    length_mm = params.free_length_mm
    cc_curvature_per_mm = float(np.linalg.norm(bend_from_tendons(tendons[-1], params.tendon_offset_mm))) / length_mm
    element_mm = friction.free_length_mm / settings.n_elements
    arc_mm = (np.arange(settings.n_elements) + 0.5) * element_mm
    curvature = friction.curvature_per_mm
    curvature_frictionless = frictionless.curvature_per_mm

    figure = new_figure(11.0, 4.8)
    shape_ax, radius_ax = figure.subplots(1, 2)
    shape_ax.add_patch(support_tube_patch(params.outer_diameter_mm))
    cc_shape = cc.backbone_mm(tendons[-1], length_mm, n_points=41)
    shape_ax.plot(cc_shape[:, 0], cc_shape[:, 2], label="constant curvature", **CC_STYLE)
    shape_ax.plot(frictionless.backbone_mm[:, 0], frictionless.backbone_mm[:, 2], marker=".",
                  label="lumped model, no friction", **FRICTIONLESS_STYLE)
    shape_ax.plot(friction.backbone_mm[:, 0], friction.backbone_mm[:, 2], marker="o", markersize=3,
                  label=f"lumped model with friction (mu = {params.mu:g})", **FRICTION_STYLE)
    shape_ax.set(xlabel="x (toward tendon 1) [mm]", ylabel="z (insertion axis) [mm]", aspect="equal",
                 title="(a) shape at 90 deg articulation")
    shape_ax.legend(loc="lower left", fontsize=8)
    shape_ax.grid(alpha=0.3)
    radius_ax.axhline(1.0 / cc_curvature_per_mm, label="constant curvature", **CC_STYLE)
    radius_ax.plot(arc_mm, 1.0 / curvature_frictionless, marker=".", label="lumped model, no friction",
                   **FRICTIONLESS_STYLE)
    radius_ax.plot(arc_mm, 1.0 / curvature, marker="o", markersize=3,
                   label=f"lumped model with friction (mu = {params.mu:g})", **FRICTION_STYLE)
    radius_ax.set(xlabel="arc length from the tube exit [mm]", ylabel="radius of curvature [mm]",
                  title="(b) radius of curvature along the arc", xlim=(0.0, length_mm))
    radius_ax.legend(fontsize=8)
    radius_ax.grid(alpha=0.3)
    figure.suptitle(f"{TITLE}: friction bends the base more than the tip")
    save_png(figure, out_dir / FIGURE)

    return {
        "figure": FIGURE,
        "articulation_deg": ARTICULATION_DEG,
        "arc_length_mm": arc_mm,
        "curvature_per_mm": curvature,
        "frictionless_curvature_per_mm": curvature_frictionless,
        "constant_curvature_per_mm": cc_curvature_per_mm,
        "curvature_base_per_mm": curvature[0],
        "curvature_tip_per_mm": curvature[-1],
        "curvature_base_to_tip_ratio": curvature[0] / curvature[-1],
        "frictionless_base_to_tip_ratio": curvature_frictionless[0] / curvature_frictionless[-1],
        "radius_base_mm": 1.0 / curvature[0],
        "radius_tip_mm": 1.0 / curvature[-1],
        "constant_curvature_radius_mm": 1.0 / cc_curvature_per_mm,
        "tip_mm": {"constant_curvature": cc.tip_mm(tendons[-1], length_mm),
                   "frictionless": frictionless.tip_mm, "friction": friction.tip_mm},
    }

