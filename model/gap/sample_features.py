"""Per-sample descriptors of what the catheter was doing: the axes the gap is broken down along.

From the model input u = u_measured - zeros [mm] and the tendon offset r, the
constant-curvature bend vector (model.constant_curvature.bend_from_tendons)

    b = ((u1 - u3)/2, (u2 - u4)/2) / r,   articulation theta = |b|,  plane phi = atan2(b_y, b_x)

and with time derivatives (central differences) the motion class of each sample:
    static          every tendon and the insertion slower than STATIC_SPEED_MM_S;
    insertion       the free length changes faster than STATIC_SPEED_MM_S;
    after reversal  the bend vector within REVERSAL_WINDOW_DEG of where its velocity db/dt turned
                    back (by more than 135 deg; passing through straight is no reversal: b moves on);
    loading         theta grows; unloading: theta shrinks;
    sideways        moving at constant articulation (circles: the plane turns).
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields

import numpy as np

from model.gap.recording import Recording

STATIC_SPEED_MM_S = 0.05
ARTICULATION_RATE_DEG_S = 2.0     # |d theta/dt| below this (while moving) is sideways motion
REVERSAL_WINDOW_DEG = 10.0
REVERSAL_COSINE = -0.7            # cos 135 deg


@dataclass(frozen=True)
class SampleFeatures:
    """Descriptors of the valid samples of several recordings, concatenated (one row per sample)."""

    articulation_deg: np.ndarray
    plane_deg: np.ndarray            # in [0, 360)
    insertion_mm: np.ndarray
    motion: np.ndarray               # str labels, see module doc
    speed_mm_s: np.ndarray           # fastest tendon
    tension_n: np.ndarray            # total tendon tension (measured, else modelled)
    time_fraction: np.ndarray        # position along its recording, 0..1
    recording: np.ndarray            # index of the recording

    def subset(self, mask: np.ndarray) -> "SampleFeatures":
        """The samples where `mask` [n] is True."""
        return SampleFeatures(*(getattr(self, f.name)[mask] for f in fields(self)))


def compute_features(recordings: Sequence[Recording], zero_offsets_mm: Sequence[float],
                     modelled_tension_n: Sequence[np.ndarray | None]) -> SampleFeatures:
    """Features of the valid samples. Tension: the log's tendon forces where measured, else (a log
    without forces, or a cell a drive did not answer) the model's; a recording's modelled tension
    [T, 4] is None where every force was measured."""
    parts = []
    for index, (r, model_tension) in enumerate(zip(recordings, modelled_tension_n)):
        u = r.tendon_mm - np.asarray(zero_offsets_mm)
        bend = bend_deg(r, zero_offsets_mm)
        theta_deg = np.hypot(bend[:, 0], bend[:, 1])
        plane_deg = np.mod(np.degrees(np.arctan2(bend[:, 1], bend[:, 0])), 360.0)
        speed = np.max(np.abs(np.gradient(u, r.t_s, axis=0)), axis=1)
        insertion_rate = np.abs(np.gradient(r.insertion_mm, r.t_s))
        theta_rate = np.gradient(theta_deg, r.t_s)
        motion = _motion(bend, theta_rate, speed, insertion_rate, r.t_s)
        force = r.tendon_force_n if model_tension is None else (
            model_tension if r.tendon_force_n is None
            else np.where(np.isfinite(r.tendon_force_n), r.tendon_force_n, model_tension))  # unmeasured: the model's
        tension = np.sum(np.clip(force, 0.0, None), axis=1)
        fraction = (r.t_s - r.t_s[0]) / max(r.t_s[-1] - r.t_s[0], 1e-12)
        valid = r.valid
        parts.append((theta_deg[valid], plane_deg[valid], r.insertion_mm[valid], motion[valid], speed[valid],
                      tension[valid], fraction[valid], np.full(int(valid.sum()), index)))
    return SampleFeatures(*(np.concatenate(columns) for columns in zip(*parts)))


def bend_deg(recording: Recording, zero_offsets_mm: Sequence[float]) -> np.ndarray:
    """[T, 2] constant-curvature bend vector of the model input, in degrees."""
    u = recording.tendon_mm - np.asarray(zero_offsets_mm)
    return np.degrees(np.column_stack([(u[:, 0] - u[:, 2]) / 2, (u[:, 1] - u[:, 3]) / 2]) / recording.tendon_offset_mm)


def reversals(bend: np.ndarray, t_s: np.ndarray) -> list[int]:
    """Samples at which the bend vector's velocity turned back by more than 135 deg (see module doc)."""
    velocity = np.gradient(bend, t_s, axis=0)
    moving = np.hypot(velocity[:, 0], velocity[:, 1]) >= ARTICULATION_RATE_DEG_S
    found = []
    last_velocity = None
    for t in np.flatnonzero(moving):
        if last_velocity is not None and velocity[t] @ last_velocity < REVERSAL_COSINE * np.hypot(*velocity[t]) \
                * np.hypot(*last_velocity):
            found.append(int(t))
        last_velocity = velocity[t]
    return found


def _motion(bend: np.ndarray, theta_rate: np.ndarray, speed: np.ndarray, insertion_rate: np.ndarray,
            t_s: np.ndarray) -> np.ndarray:
    labels = np.where(theta_rate > 0, "loading", "unloading").astype(object)
    labels[np.abs(theta_rate) < ARTICULATION_RATE_DEG_S] = "sideways"
    starts = reversals(bend, t_s)
    for start, stop in zip(starts, starts[1:] + [len(bend)]):
        near = np.hypot(*(bend[start:stop] - bend[start]).T) < REVERSAL_WINDOW_DEG
        window = np.arange(start, stop)[near & (labels[start:stop] != "sideways")]
        labels[window] = "after reversal"
    labels[insertion_rate >= STATIC_SPEED_MM_S] = "insertion"
    labels[(speed < STATIC_SPEED_MM_S) & (insertion_rate < STATIC_SPEED_MM_S)] = "static"
    return labels.astype(str)
