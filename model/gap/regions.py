"""Where the gap lies: the held-out tip error broken down by region of the motion.

For a region R of the samples (errors e_t, Euclidean tip error |e_t|):

    rmse_R = sqrt(mean_{t in R} |e_t|^2)
    share_R = sum_{t in R} |e_t|^2 / sum_t |e_t|^2        (its part of the total squared error)
    concentration_R = share_R / (|R| / n)                 (1: as much error as samples; 2: twice)

Regions come in groups (articulation, bending plane, insertion, motion, speed, tension,
time); within a group they do not overlap. The gap concentrates where the concentration is
at least CONCENTRATED and the region holds at least MIN_SAMPLE_FRACTION of the samples.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from model.gap.sample_features import SampleFeatures

ARTICULATION_EDGES_DEG = (0.0, 15.0, 45.0, 75.0, 105.0, 135.0, np.inf)
MIN_PLANE_ARTICULATION_DEG = 15.0
SPEED_EDGES_MM_S = (0.05, 2.0, 6.0)
MOTIONS = ("static", "loading", "unloading", "after reversal", "sideways", "insertion")
TIME_BINS = 5
MIN_SAMPLES = 10
CONCENTRATED = 1.5
MIN_SAMPLE_FRACTION = 0.05
_PLANE_NAMES = {0: "+x, tendon 1", 90: "+y, tendon 2", 180: "-x, tendon 3", 270: "-y, tendon 4"}


@dataclass(frozen=True)
class Region:
    group: str
    name: str
    mask: np.ndarray


def regions(features: SampleFeatures) -> list[Region]:
    """Every region of every group with at least MIN_SAMPLES samples."""
    f = features
    found: list[Region] = []

    def add(group: str, name: str, mask: np.ndarray) -> None:
        if mask.sum() >= MIN_SAMPLES:
            found.append(Region(group, name, mask))

    for low, high in zip(ARTICULATION_EDGES_DEG[:-1], ARTICULATION_EDGES_DEG[1:]):
        name = f"articulation {low:g}-{high:g} deg" if np.isfinite(high) else f"articulation > {low:g} deg"
        add("articulation", name, (f.articulation_deg >= low) & (f.articulation_deg < high))
    bent = f.articulation_deg >= MIN_PLANE_ARTICULATION_DEG
    for centre in range(0, 360, 45):
        offset = np.mod(f.plane_deg - centre + 22.5, 360.0)
        label = f" ({_PLANE_NAMES[centre]})" if centre in _PLANE_NAMES else ""
        add("plane", f"plane {centre} deg{label}", bent & (offset < 45.0))
    low, high = float(f.insertion_mm.min()), float(f.insertion_mm.max())
    if high - low >= 1.0:
        edges = np.linspace(low, high, 5)
        for a, b in zip(edges[:-1], edges[1:]):
            add("insertion", f"insertion {a:.0f}-{b:.0f} mm",
                (f.insertion_mm >= a) & ((f.insertion_mm < b) | (b == high)))
    for motion in MOTIONS:
        add("motion", motion, f.motion == motion)
    speed_names = ("at rest", "slow", "medium", "fast")
    edges = (-np.inf,) + SPEED_EDGES_MM_S + (np.inf,)
    for name, a, b in zip(speed_names, edges[:-1], edges[1:]):
        label = f"speed {name} (< {b:g} mm/s)" if a == -np.inf else \
            f"speed {name} (>= {a:g} mm/s)" if b == np.inf else f"speed {name} ({a:g}-{b:g} mm/s)"
        add("speed", label, (f.speed_mm_s >= a) & (f.speed_mm_s < b))
    if np.ptp(f.tension_n) > 0:
        quartiles = np.quantile(f.tension_n, [0.0, 0.25, 0.5, 0.75, 1.0])
        for a, b in zip(quartiles[:-1], quartiles[1:]):
            add("tension", f"tension {a:.1f}-{b:.1f} N", (f.tension_n >= a) & ((f.tension_n < b) | (b == quartiles[-1])))
    for k in range(TIME_BINS):
        a, b = k / TIME_BINS, (k + 1) / TIME_BINS
        add("time", f"time {100 * a:.0f}-{100 * b:.0f} %", (f.time_fraction >= a) & ((f.time_fraction < b) | (b == 1.0)))
    return found


def breakdown(found: Sequence[Region], errors_mm: np.ndarray) -> list[dict]:
    """rmse, share and concentration per region (see module doc), most concentrated first.

    "order" is the region's place in `regions` (groups in turn, bins in ascending order).
    """
    squared = np.sum(np.asarray(errors_mm) ** 2, axis=1)
    total = float(squared.sum()) or 1.0
    n = len(squared)
    rows = []
    for order, region in enumerate(found):
        part = squared[region.mask]
        share = float(part.sum()) / total
        fraction = len(part) / n
        rows.append({"region": region.name, "group": region.group, "rmse_mm": float(np.sqrt(part.mean())),
                     "share": share, "sample_fraction": fraction, "concentration": share / fraction,
                     "samples": int(len(part)), "order": order})
    return sorted(rows, key=lambda row: -row["concentration"])


def concentrated(rows: Sequence[dict]) -> list[dict]:
    """The regions where the gap concentrates (see module doc), most concentrated first."""
    return [row for row in rows if row["concentration"] >= CONCENTRATED and row["sample_fraction"] >= MIN_SAMPLE_FRACTION]


def shrink_by_region(found: Sequence[Region], before_mm: np.ndarray, after_mm: np.ndarray) -> list[dict]:
    """RMSE before and after, and the shrink 1 - after/before, per region."""
    before_sq = np.sum(np.asarray(before_mm) ** 2, axis=1)
    after_sq = np.sum(np.asarray(after_mm) ** 2, axis=1)
    rows = []
    for region in found:
        b = float(np.sqrt(before_sq[region.mask].mean()))
        a = float(np.sqrt(after_sq[region.mask].mean()))
        rows.append({"region": region.name, "group": region.group, "before_mm": b, "after_mm": a,
                     "shrink": 1.0 - a / b if b > 0 else 0.0})
    return rows
