"""Figures of the paper reproduction: created without pyplot (no global backend), saved as PNG."""
from __future__ import annotations

from pathlib import Path

from matplotlib import colormaps
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle

DPI = 110
CC_STYLE = {"color": "0.35", "linestyle": "--", "linewidth": 1.5}
FRICTIONLESS_STYLE = {"color": "tab:green", "linestyle": ":", "linewidth": 1.8}
FRICTION_STYLE = {"color": "tab:red", "linewidth": 2.0}


def new_figure(width_in: float, height_in: float) -> Figure:
    """A figure drawn by the Agg renderer, independent of any pyplot state."""
    figure = Figure(figsize=(width_in, height_in), layout="constrained")
    FigureCanvasAgg(figure)
    return figure


def save_png(figure: Figure, path: Path) -> Path:
    figure.savefig(path, dpi=DPI, format="png")
    return path


def sweep_colors(count: int) -> list:
    """One colour per value of an ascending sweep, light (smallest) to dark (largest)."""
    cmap = colormaps["viridis"]
    return [cmap(0.85 - 0.75 * i / max(count - 1, 1)) for i in range(count)]


def support_tube_patch(outer_diameter_mm: float, depth_mm: float = 12.0) -> Rectangle:
    """The rigid support tube below its exit plane z = 0, seen from the side, as a grey patch."""
    return Rectangle((-outer_diameter_mm / 2, -depth_mm), outer_diameter_mm, depth_mm, color="0.8",
                     label="support tube")
