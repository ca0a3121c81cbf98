"""The tracker noise floor: how small a tip error the data can resolve.

During static holds (inputs unchanged) the true tip is constant or drifts slowly, so the
second difference of consecutive measured tips is pure noise: for white noise of std sigma
per axis,

    d2(j) = x(j+1) - 2 x(j) + x(j-1),   var(d2) = 6 sigma^2,

over consecutive tip samples j (rows without a tip, such as those between the frames of a
tracker slower than the log, are skipped). sigma is taken robustly as
1.4826 * median|d2| / sqrt(6) over all axes. Without enough static holds, tips measured at
20 Hz or more use every triple (the smooth motion adds little at that rate, so this is a slight
overestimate); slower ones (e.g. sequences of static poses) give no estimate.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from model.gap.recording import Recording

MIN_TRIPLES = 30
MIN_RATE_FOR_MOVING_ESTIMATE_HZ = 20.0


def tracker_noise_mm(recordings: Sequence[Recording]) -> float | None:
    """Per-axis tip noise std (mm), or None when the recordings cannot tell."""
    static, moving = [], []
    for r in recordings:
        measured = np.flatnonzero(r.valid)
        if len(measured) < 3:
            continue
        tip = r.tip_mm[measured]
        d2 = tip[2:] - 2 * tip[1:-1] + tip[:-2]
        inputs = np.column_stack([r.tendon_mm, r.insertion_mm])[measured]
        still = np.all(inputs[2:] == inputs[1:-1], axis=1) & np.all(inputs[1:-1] == inputs[:-2], axis=1)
        static.append(d2[still])
        if 1.0 / float(np.median(np.diff(r.t_s[measured]))) >= MIN_RATE_FOR_MOVING_ESTIMATE_HZ:
            moving.append(d2)
    for pool in (static, moving):
        values = np.abs(np.concatenate(pool)).ravel() if pool else np.empty(0)
        if len(values) >= 3 * MIN_TRIPLES:
            return float(1.4826 * np.median(values) / np.sqrt(6.0))
    return None
