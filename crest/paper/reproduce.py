"""Run every simulation study of the seed paper, write one PNG per figure and summary.json."""
from __future__ import annotations

import dataclasses
import json
import time
from pathlib import Path
from typing import TextIO

import numpy as np

from crest.paper import fig_3_1, fig_3_2, fig_4_1, fig_4_2, fig_4_3, fig_4_4
from crest.paper.settings import PaperSettings

STUDIES = (fig_3_1, fig_3_2, fig_4_1, fig_4_2, fig_4_3, fig_4_4)
SUMMARY = "summary.json"
PAPER = ("Jung, Penning, Ferrier, Zinn: A Modeling Approach for Continuum Robotic Manipulators: "
         "Effects of Nonlinear Internal Device Friction (seed paper, sections III-IV)")
PAPER_FRICTION_ERROR_CM = 0.31
PAPER_CC_ERROR_CM = "more than 1"


def headline(fig_3_2_numbers: dict, mu: float) -> dict:
    """The paper's headline (tip error at 180 deg on its prototype) next to what we can compute."""
    difference_cm = fig_3_2_numbers["end_difference_cc_vs_friction_mm"] / 10.0
    return {
        "cc_vs_friction_tip_difference_at_180_deg_cm": difference_cm,
        "paper_friction_model_error_cm": PAPER_FRICTION_ERROR_CM,
        "paper_constant_curvature_error_cm": PAPER_CC_ERROR_CM,
        "note": (f"The paper's {PAPER_FRICTION_ERROR_CM} cm (friction model) and {PAPER_CC_ERROR_CM} cm "
                 "(constant curvature) are tip errors against its prototype's measured tip at 180 deg. "
                 "We have no prototype data, so this reports how far our friction model's tip "
                 f"(mu = {mu:g}) lies from the constant-curvature tip for the same tendon input: "
                 f"{difference_cm:.2f} cm. It is the error constant curvature would make on a catheter "
                 "that behaves like our model; it is not a validation against hardware."),
    }


def require_finite(numbers, where: str) -> None:
    """Raise if any number a study returned is NaN or infinite (a diverged model run)."""
    if isinstance(numbers, dict):
        for key, value in numbers.items():
            require_finite(value, f"{where}.{key}")
    elif isinstance(numbers, (list, tuple)):
        for value in numbers:
            require_finite(value, where)
    elif isinstance(numbers, (float, np.ndarray)) and not np.all(np.isfinite(numbers)):
        raise ArithmeticError(f"{where} is not finite: the catheter model's solver diverged for these "
                              "parameters; try other [friction] values in the catheter TOML")


def _to_json(value):
    """numpy arrays and scalars as plain JSON values."""
    if hasattr(value, "tolist"):
        return value.tolist()
    raise TypeError(f"summary value of type {type(value).__name__} is not JSON serialisable")


def reproduce(out_dir: str | Path, settings: PaperSettings, progress: TextIO | None = None) -> dict:
    """Run all studies into out_dir (created if missing); returns the summary written to summary.json.

    One progress line per study goes to `progress` (e.g. sys.stderr; None for silence).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    figures = {}
    for index, study in enumerate(STUDIES, start=1):
        started = time.perf_counter()
        name = Path(study.FIGURE).stem
        figures[name] = study.run(settings, out)
        require_finite(figures[name], name)
        if progress is not None:     # one whole line per study, so a compile notice never splits it
            print(f"crest paper [{index}/{len(STUDIES)}] {study.TITLE}: {study.FIGURE} in "
                  f"{time.perf_counter() - started:.1f} s", file=progress, flush=True)
    summary = {
        "paper": PAPER,
        "settings": {"n_elements": settings.n_elements, "mu_sweep": settings.mu_sweep,
                     "circle_articulations_deg": settings.circle_articulations_deg,
                     "history_move_deg": settings.history_move_deg, "step_deg": settings.step_deg,
                     "params": dataclasses.asdict(settings.params)},
        "headline": headline(figures["fig_3_2"], settings.params.mu),
        "figures": figures,
    }
    (out / SUMMARY).write_text(json.dumps(summary, indent=1, default=_to_json) + "\n")
    return summary
