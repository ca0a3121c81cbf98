"""The tracker noise floor: how small a tip error the data can resolve.

During static holds (inputs unchanged) the true tip is constant or drifts slowly, so the
second difference of consecutive measured tips is pure noise: for white noise of std sigma
per axis,

    d2(j) = x(j+1) - 2 x(j) + x(j-1),   var(d2) = 6 sigma^2,

over consecutive tip samples j (rows without a tip, such as those between the frames of a
tracker slower than the log, are skipped). sigma is taken robustly as
1.4826 * median|d2| / sqrt(6) over all axes. Without enough static holds, tips measured at
20 Hz or more use every triple (the smooth motion adds little at that rate, so this is a slight
overestimate). Slower ones (sequences of static poses) still tell the noise when they repeat a
path: where the inputs repeat with a period of P rows (the same sweep run again), the pose at row
t + P is reached along the same path as at row t, so from the second period on

    d(t) = x(t + P) - x(t),   var(d) = 2 sigma^2,

and sigma = 1.4826 * median|d| / sqrt(2) (slow drift between repetitions makes this an
overestimate: fewer effects are then called significant, not more). Otherwise no estimate.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from model.gap.recording import Recording

MIN_TRIPLES = 30
MIN_RATE_FOR_MOVING_ESTIMATE_HZ = 20.0


def tracker_noise_mm(recordings: Sequence[Recording]) -> float | None:
    """Per-axis tip noise std (mm), or None when the recordings cannot tell."""
    static, moving, repeated = [], [], []
    for r in recordings:
        repeated.append(_repeat_differences(r))
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
    for pool, variance_factor in ((static, 6.0), (moving, 6.0), (repeated, 2.0)):
        values = np.abs(np.concatenate(pool)).ravel() if pool else np.empty(0)
        if len(values) >= 3 * MIN_TRIPLES:
            return float(1.4826 * np.median(values) / np.sqrt(variance_factor))
    return None


def _repeat_differences(r: Recording) -> np.ndarray:
    """x(t + P) - x(t) [n, 3] from the second period on, for the shortest period P with which the
    recording's inputs repeat exactly (empty when they do not repeat at least twice over)."""
    inputs = np.column_stack([r.tendon_mm, r.insertion_mm])
    n = len(inputs)
    if np.all(inputs[1:] == inputs[:-1]):
        return np.empty((0, 3))                 # one static hold: the static estimate's case
    starts_again = np.flatnonzero(np.all(inputs == inputs[0], axis=1))      # the periods it can have
    for period in starts_again[(starts_again >= 2) & (starts_again <= n // 2)]:
        if np.array_equal(inputs[period:], inputs[:-period]):
            later = np.arange(period, n - period)
            both = r.valid[later] & r.valid[later + period]
            return r.tip_mm[later + period][both] - r.tip_mm[later][both]
    return np.empty((0, 3))
