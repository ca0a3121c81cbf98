"""Does the training log cover what the held-out log asks the model to predict?

The base model is calibrated where the training logs went. A held-out sample beyond that, at an
articulation theta more than ARTICULATION_MARGIN_DEG above the training's largest, or at a free
length more than INSERTION_MARGIN_MM outside the training's range, is extrapolation: the
calibration's error there says little about a missing effect, and a candidate may be named for what
the training never showed. Where at least EXTRAPOLATED_SHARE of the held-out samples are such, the
diagnosis says so (`coverage_lines`), before its verdict is read.

Articulation is the constant-curvature bend of the model input (`bend_deg`, the tendons less the
baseline's fitted zeros), theta = |b|, over each recording's valid samples (those with a tip).
The standard excitations (`control.excitation`) stay inside it: the short held-out excitation reaches
115 deg against the short training's 100 deg, with 6% of its samples above 110 deg, and the full one
125 deg against 130 deg; all four span 56-92 mm of free length (`tests/gap/test_coverage.py`).
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from model.gap.recording import Recording
from model.gap.sample_features import bend_deg

ARTICULATION_MARGIN_DEG = 10.0
INSERTION_MARGIN_MM = 5.0
EXTRAPOLATED_SHARE = 0.1


def coverage_lines(train: Sequence[Recording], held: Sequence[Recording],
                   zero_offsets_mm: Sequence[float]) -> list[str]:
    """One line per way the held-out samples leave the training's range (empty: they stay in it)."""
    def spans(recordings: Sequence[Recording]) -> tuple[np.ndarray, np.ndarray]:
        theta = [np.hypot(*bend_deg(r, zero_offsets_mm)[r.valid].T) for r in recordings]
        return np.concatenate(theta), np.concatenate([r.insertion_mm[r.valid] for r in recordings])

    train_deg, train_mm = spans(train)
    held_deg, held_mm = spans(held)
    lines = []
    top_deg = float(train_deg.max())
    beyond = held_deg > top_deg + ARTICULATION_MARGIN_DEG
    if beyond.mean() >= EXTRAPOLATED_SHARE:
        lines.append(f"the held-out logs bend further than the training logs: {100 * beyond.mean():.0f}% of their "
                     f"samples lie above the training's largest articulation ({top_deg:.0f} deg; up to "
                     f"{held_deg.max():.0f} deg), where the calibration extrapolates")
    low_mm, high_mm = float(train_mm.min()), float(train_mm.max())
    outside = (held_mm < low_mm - INSERTION_MARGIN_MM) | (held_mm > high_mm + INSERTION_MARGIN_MM)
    if outside.mean() >= EXTRAPOLATED_SHARE:
        lines.append(f"the held-out logs reach free lengths the training logs did not: {100 * outside.mean():.0f}% of "
                     f"their samples lie outside the training's {low_mm:.0f}-{high_mm:.0f} mm ({held_mm.min():.0f}-"
                     f"{held_mm.max():.0f} mm), where the calibration extrapolates")
    return lines
