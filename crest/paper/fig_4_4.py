"""Fig. 4.4: history dependence of the tip motion at 180 deg articulation (paper IV).

Two starts at the same 180 deg input. Without previous motion: the frictionless model is
articulated to 180 deg and its state is restored into the friction model, so every Dahl
force starts at zero (the zero crossing of the Dahl curve, paper eq. 1) and grows alike for
either direction of motion. With previous motion: the friction model itself is articulated
from 0 to 180 deg, so the tendons arrive with large Dahl forces opposing the pull; a move
that keeps pulling continues along the saturated branch, a move that releases first has
to unload it, and the two directions differ.

From each start the command moves left and right by `history_move_deg` in the bending
plane (theta = 180 +- a) and sideways (bending plane phi = +-a, for which constant
curvature keeps the tip in the horizontal plane z = 0). The instantaneous direction of a
move is the direction of the tip displacement over its first sample (`step_deg`).
"""
from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

import numpy as np

from crest.paper.figure_output import CC_STYLE, new_figure, save_png
from crest.paper.input_paths import articulation_ramp_mm, articulation_tendons_mm, ramp
from crest.paper.settings import PaperSettings
from model import ConstantCurvature, DahlCatheter

FIGURE = "fig_4_4.png"
TITLE = "Fig. 4.4 history dependence at 180 deg"
ARTICULATION_DEG = 180.0
CASES = ("without_previous_motion", "with_previous_motion")
# name: (sign of the articulation change, sign of the plane change, view axes (horizontal, vertical))
MOVES = {"articulate_more": (1.0, 0.0, (0, 2)), "articulate_less": (-1.0, 0.0, (0, 2)),
         "sideways_positive": (0.0, 1.0, (1, 2)), "sideways_negative": (0.0, -1.0, (1, 2))}
AXIS_NAMES = ("x", "y", "z")
ARROW_MM = 8.0


class MovePath(NamedTuple):
    """One move from one start: tip paths [T, 3] and first-step displacements [3], all in mm."""

    start: np.ndarray
    tips: np.ndarray
    cc_tips: np.ndarray
    direction: np.ndarray
    cc_direction: np.ndarray


def start_states(settings: PaperSettings) -> dict:
    """The two friction-model states at 180 deg, by case name."""
    params = settings.params
    to_180 = articulation_ramp_mm(params, 0.0, ARTICULATION_DEG, settings.step_deg)
    frictionless = DahlCatheter(params.frictionless(), settings.n_elements)
    frictionless.run(to_180)
    with_history = DahlCatheter(params, settings.n_elements)
    with_history.run(to_180)
    return {"without_previous_motion": frictionless.snapshot(), "with_previous_motion": with_history.snapshot()}


def move_tendons_mm(settings: PaperSettings, move: str) -> np.ndarray:
    """Tendon inputs [T, 4] of one left/right move from 180 deg in the bending plane phi = 0."""
    theta_sign, plane_sign, _ = MOVES[move]
    offsets = ramp(0.0, settings.history_move_deg, settings.step_deg)
    return articulation_tendons_mm(settings.params, ARTICULATION_DEG + theta_sign * offsets, plane_sign * offsets)


def angle_between_deg(a: np.ndarray, b: np.ndarray) -> float:
    cosine = np.dot(a, b) / (np.linalg.norm(a) * np.linalg.norm(b))
    return float(np.rad2deg(np.arccos(np.clip(cosine, -1.0, 1.0))))


def view_angle_deg(direction: np.ndarray, axes: tuple[int, int]) -> float:
    """Direction angle in a view plane, from its horizontal axis toward its vertical axis [deg]."""
    return float(np.rad2deg(np.arctan2(direction[axes[1]], direction[axes[0]])))


def run(settings: PaperSettings, out_dir: Path) -> dict:
    """Both starts, all four moves: tip paths, instantaneous directions and their differences."""
    params = settings.params
    length_mm = params.free_length_mm
    cc = ConstantCurvature(params)
    states = start_states(settings)
    cc_start = cc.tip_mm(articulation_tendons_mm(params, ARTICULATION_DEG, 0.0)[0], length_mm)
    paths = {}
    cases = {}
    for case in CASES:
        model = DahlCatheter(params, settings.n_elements)
        model.restore(states[case])
        start = model.tip_mm.copy()
        moves = {}
        for move, (_, _, axes) in MOVES.items():
            tendons = move_tendons_mm(settings, move)
            model.restore(states[case])
            tips = model.run(tendons)
            cc_tips = np.array([cc.tip_mm(u, length_mm) for u in tendons])
            direction = tips[0] - start
            cc_direction = cc_tips[0] - cc_start
            paths[case, move] = MovePath(start, tips, cc_tips, direction, cc_direction)
            moves[move] = {"direction_unit": direction / np.linalg.norm(direction),
                           "first_step_mm": float(np.linalg.norm(direction)),
                           "view_axes": [AXIS_NAMES[a] for a in axes],
                           "direction_deg": view_angle_deg(direction, axes),
                           "cc_direction_deg": view_angle_deg(cc_direction, axes),
                           "deviation_from_cc_direction_deg": angle_between_deg(direction, cc_direction),
                           "end_tip_mm": tips[-1],
                           "end_distance_from_cc_mm": float(np.linalg.norm(tips[-1] - cc_tips[-1]))}
        more, less = (paths[case, m].direction for m in ("articulate_more", "articulate_less"))
        cases[case] = {"start_tip_mm": start, "moves": moves,
                       "reversal_asymmetry_deg": angle_between_deg(more, -less),
                       "reversal_step_ratio": float(np.linalg.norm(more) / np.linalg.norm(less))}
    difference = {}
    for move in MOVES:
        fresh, loaded = paths[CASES[0], move], paths[CASES[1], move]
        difference[move] = {"direction_difference_deg": angle_between_deg(fresh.direction, loaded.direction),
                            "end_point_difference_mm": float(np.linalg.norm(fresh.tips[-1] - loaded.tips[-1]))}
    _draw(settings, paths, cc_start, out_dir / FIGURE)
    return {"figure": FIGURE, "articulation_deg": ARTICULATION_DEG, "move_deg": settings.history_move_deg,
            "first_step_deg": settings.step_deg, "cc_start_tip_mm": cc_start, "cases": cases,
            "difference": difference,
            "max_direction_difference_deg": max(d["direction_difference_deg"] for d in difference.values()),
            "start_difference_mm": float(np.linalg.norm(cases[CASES[0]]["start_tip_mm"]
                                                        - cases[CASES[1]]["start_tip_mm"]))}


def _arrow(ax, origin: np.ndarray, vector: np.ndarray, view: tuple[int, int], color) -> None:
    """An arrow of length ARROW_MM from origin along vector, projected on the view axes."""
    h, v = view
    tip = origin + ARROW_MM * vector / np.linalg.norm(vector)
    ax.annotate("", xy=(tip[h], tip[v]), xytext=(origin[h], origin[v]),
                arrowprops={"arrowstyle": "-|>", "color": color, "linewidth": 2.0})


def _square_window(points: list, margin_mm: float = 2.0) -> tuple:
    """(x limits, y limits) of one square window that holds all the given 2D points."""
    stacked = np.vstack(points)
    low, high = stacked.min(axis=0), stacked.max(axis=0)
    centre = (low + high) / 2
    half = (high - low).max() / 2 + margin_mm
    return (centre[0] - half, centre[0] + half), (centre[1] - half, centre[1] + half)


def _draw(settings: PaperSettings, paths: dict, cc_start: np.ndarray, path: Path) -> None:
    figure = new_figure(12.0, 10.0)
    axes = figure.subplots(2, 2)
    move_deg = settings.history_move_deg
    styles = {"articulate_more": ("tab:red", f"articulate to {ARTICULATION_DEG + move_deg:g} deg"),
              "articulate_less": ("tab:blue", f"articulate to {ARTICULATION_DEG - move_deg:g} deg"),
              "sideways_positive": ("tab:red", f"plane to +{move_deg:g} deg (toward tendon 2)"),
              "sideways_negative": ("tab:blue", f"plane to -{move_deg:g} deg (toward tendon 4)")}
    columns = ((("articulate_more", "articulate_less"), "in the bending plane"),
               (("sideways_positive", "sideways_negative"), "sideways"))
    windows = [_square_window([np.vstack([cc_start, paths[case, move].start, paths[case, move].tips,
                                          paths[case, move].cc_tips])[:, list(MOVES[move][2])]
                               for case in CASES for move in moves]) for moves, _ in columns]
    for row, case in enumerate(CASES):
        for column, (moves, kind) in enumerate(columns):
            ax = axes[row, column]
            for move in moves:
                start, tips, cc_tips, direction, cc_direction = paths[case, move]
                view = h, v = MOVES[move][2]
                color, label = styles[move]
                cc_path = np.vstack([cc_start, cc_tips])
                ax.plot(cc_path[:, h], cc_path[:, v], label="constant curvature" if move == moves[0] else None,
                        **CC_STYLE)
                ax.plot(np.r_[start[h], tips[:, h]], np.r_[start[v], tips[:, v]], linestyle=":", linewidth=2.0,
                        color=color, label=label)
                _arrow(ax, cc_start, cc_direction, view, CC_STYLE["color"])
                _arrow(ax, start, direction, view, color)
                ax.plot(start[h], start[v], marker="o", color="k")
            ax.set(xlabel=f"{AXIS_NAMES[h]} [mm]", ylabel=f"{AXIS_NAMES[v]} [mm]", aspect="equal",
                   xlim=windows[column][0], ylim=windows[column][1],
                   title=f"({'ab'[row]}) {case.replace('_', ' ')}: moves {kind}")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7, loc="best")
    figure.suptitle(f"{TITLE}: arrows = instantaneous tip directions (grey: constant curvature), "
                    f"dotted = resulting paths (mu = {settings.params.mu:g})")
    save_png(figure, path)
