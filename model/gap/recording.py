"""One experiment as arrays: what the gap analysis works on (it never reads files).

Positions are the MEASURED drive positions (tendon displacement, positive = pulled, and
free length), because the model is driven by what the drives did, not by what they were told.
"""
from __future__ import annotations

import functools
import hashlib
from dataclasses import dataclass

import numpy as np


class RecordingError(ValueError):
    """A recording cannot be analysed (shapes, missing tip samples, inconsistent geometry)."""


@dataclass(frozen=True)
class Recording:
    """T samples of one experiment (units in the names).

    tendon_mm: [T, 4] measured tendon displacements for tendons at 0, 90, 180, 270 deg.
    insertion_mm: [T] measured free length out of the support tube.
    Both drive the model and must be finite on every sample (a loader fills a sample whose position
    was not measured before building the recording).
    tip_mm: [T, 3] measured tip in the base frame; NaN rows are missing tracker samples.
    tendon_force_n: [T, 4] measured tendon tension, or None when the log has none.
    flexible_length_mm, tendon_offset_mm, outer_diameter_mm: the catheter's geometry
    (outer diameter None when unknown).
    """

    name: str
    t_s: np.ndarray
    tendon_mm: np.ndarray
    insertion_mm: np.ndarray
    tip_mm: np.ndarray
    tendon_force_n: np.ndarray | None
    flexible_length_mm: float
    tendon_offset_mm: float
    outer_diameter_mm: float | None

    def __post_init__(self) -> None:
        n = len(self.t_s)
        expected = {"tendon_mm": (n, 4), "insertion_mm": (n,), "tip_mm": (n, 3)}
        if self.tendon_force_n is not None:
            expected["tendon_force_n"] = (n, 4)
        for field, shape in expected.items():
            if np.shape(getattr(self, field)) != shape:
                raise RecordingError(f"{self.name}: {field} has shape {np.shape(getattr(self, field))}, "
                                     f"expected {shape} (t_s has {n} samples)")
        if n < 3:
            raise RecordingError(f"{self.name}: {n} samples; a recording needs at least 3")
        if not np.all(np.diff(self.t_s) > 0):
            raise RecordingError(f"{self.name}: t_s must increase strictly")
        for field in ("tendon_mm", "insertion_mm"):
            finite = np.isfinite(getattr(self, field))
            if not finite.all():
                sample = int(np.argmin(finite.reshape(n, -1).all(axis=1)))
                raise RecordingError(f"{self.name}: {field} is not finite at sample {sample} (t = "
                                     f"{float(self.t_s[sample]):g} s); the positions drive the model, so fill "
                                     "samples without a measured position before building the recording")
        if not self.valid.any():
            raise RecordingError(f"{self.name}: no tip sample is present; the gap needs measured tips")

    def __len__(self) -> int:
        return len(self.t_s)

    @property
    def valid(self) -> np.ndarray:
        """[T] rows with a tip sample."""
        return np.all(np.isfinite(self.tip_mm), axis=1)

    @property
    def sample_period_s(self) -> float:
        """Median time between samples."""
        return float(np.median(np.diff(self.t_s)))

    @property
    def max_summed_tension_n(self) -> float | None:
        """The largest sum of the four measured tendon tensions over the samples (missing values count
        as 0), or None when the log has no tensions or none is finite."""
        if self.tendon_force_n is None or not np.isfinite(self.tendon_force_n).any():
            return None
        return float(np.max(np.nansum(self.tendon_force_n, axis=1)))

    @functools.cached_property
    def input_digest(self) -> bytes:
        """A digest of what drives the model (times, tendon and insertion positions): equal inputs, equal runs."""
        digest = hashlib.blake2b(digest_size=16)
        for array in (self.t_s, self.tendon_mm, self.insertion_mm):
            digest.update(np.ascontiguousarray(array, dtype=float).tobytes())
        return digest.digest()

    def decimated(self, factor: int) -> "Recording":
        """About every `factor`-th sample: from each block of `factor` samples the first one with a tip
        (the block's first when none has one). Factor 1 returns self.

        A log written at the control rate holds the tracker's slower frames (rows between them
        have no tip), and the tracker drops frames; picking the first measured row of each block
        keeps a tip in every block that has one. The model interpolates the input linearly
        between kept samples, so decimation is harmless as long as the input path is smooth on
        the scale of `factor` samples.
        """
        if factor <= 1:
            return self
        valid = self.valid
        keep = []
        for start in range(0, len(self), int(factor)):
            block = valid[start:start + int(factor)]
            keep.append(start + int(np.argmax(block)) if block.any() else start)
        return self._subset(np.array(keep))

    def head(self, count: int) -> "Recording":
        """The first `count` samples."""
        return self if count >= len(self) else self._subset(slice(0, int(count)))

    def _subset(self, keep: slice | np.ndarray) -> "Recording":
        force = None if self.tendon_force_n is None else self.tendon_force_n[keep]
        return Recording(self.name, self.t_s[keep], self.tendon_mm[keep], self.insertion_mm[keep],
                         self.tip_mm[keep], force, self.flexible_length_mm, self.tendon_offset_mm,
                         self.outer_diameter_mm)
