"""Excitation trajectories for calibration and gap diagnosis (`crest excite`).

Each trajectory is a sampled set-point path: tendon displacements [T, 4] (mm, positive =
pulled) and free length [T] (mm). It is written in articulation coordinates, the bend vector
b = theta * (cos phi, sin phi) [rad] of the whole catheter and the free length L, and mapped
to tendons by the constant-curvature inverse (model.constant_curvature):

    u_k = r * (b_x cos phi_k + b_y sin phi_k) + pretension,   phi_k = (k - 1) * 90 deg.

The primitives each expose one effect's signature:
- planar sweeps through straight at several amplitudes and speeds (rate dependence,
  tension-dependent losses, torsion in each plane);
- reversals with minor loops (dead band after reversal: backlash, Dahl stiffness);
- insertion changes at constant articulation, straight and bent (tube friction, gravity,
  precurvature, which all scale with free length);
- circles in both directions (out-of-plane coupling, direction dependence);
- static holds (bias at rest: tracker offset, gravity; rate effects vanish there).
Transitions are raised cosines, so the path is smooth: its set-points can be followed by
drives with acceleration limits and decimated for fitting without losing reversals.
Training and held-out trajectories use different planes, amplitudes and speeds.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from model.constant_curvature import TENDON_ANGLES_RAD
from model.params import CatheterParams


@dataclass(frozen=True)
class ExcitationGeometry:
    """What the trajectories need to know about the catheter (mm)."""

    tendon_offset_mm: float
    free_length_mm: float
    min_free_length_mm: float
    max_free_length_mm: float
    pretension_mm: float = 0.02

    @classmethod
    def from_params(cls, params: CatheterParams, pretension_mm: float = 0.02) -> "ExcitationGeometry":
        return cls(params.tendon_offset_mm, params.free_length_mm, params.min_free_length_mm,
                   params.max_free_length_mm, pretension_mm)

    def insertion_range_mm(self) -> tuple[float, float]:
        """The free-length excursion: 30 % below to 15 % above nominal, inside the limits."""
        return (max(self.min_free_length_mm, 0.7 * self.free_length_mm),
                min(self.max_free_length_mm, 1.15 * self.free_length_mm))


@dataclass(frozen=True)
class Segment:
    """A named part of a trajectory over [start_s, stop_s)."""

    label: str
    start_s: float
    stop_s: float


@dataclass(frozen=True)
class Trajectory:
    """Set-points over time: t_s [T], tendon_mm [T, 4], insertion_mm [T] (free length)."""

    name: str
    t_s: np.ndarray
    tendon_mm: np.ndarray
    insertion_mm: np.ndarray
    segments: tuple[Segment, ...]

    @property
    def duration_s(self) -> float:
        return float(self.t_s[-1] - self.t_s[0])

    def repeated(self, duration_s: float) -> "Trajectory":
        """This trajectory played back to back until it lasts at least duration_s (e.g. for benchmarks)."""
        count = max(1, math.ceil(duration_s / (self.duration_s + self.t_s[1] - self.t_s[0])))
        dt = self.t_s[1] - self.t_s[0]
        n = len(self.t_s)
        t = np.arange(n * count) * dt
        return Trajectory(f"{self.name} x{count}", t, np.tile(self.tendon_mm, (count, 1)),
                          np.tile(self.insertion_mm, count), self.segments)


class _Builder:
    """Appends smooth articulation segments sampled at a fixed rate."""

    def __init__(self, geometry: ExcitationGeometry, sample_rate_hz: float):
        if not sample_rate_hz > 0:
            raise ValueError(f"sample_rate_hz must be > 0, got {sample_rate_hz!r}")
        self.geometry = geometry
        self.dt_s = 1.0 / sample_rate_hz
        self.bend = [np.zeros((1, 2))]
        self.length = [np.array([geometry.free_length_mm])]
        self.segments: list[Segment] = []
        self.time_s = 0.0

    @property
    def current(self) -> tuple[np.ndarray, float]:
        return self.bend[-1][-1].copy(), float(self.length[-1][-1])

    def _append(self, label: str, bend: np.ndarray, length: np.ndarray) -> None:
        self.bend.append(bend)
        self.length.append(length)
        duration = len(length) * self.dt_s
        self.segments.append(Segment(label, self.time_s, self.time_s + duration))
        self.time_s += duration

    def _time(self, duration_s: float) -> np.ndarray:
        """Local times of a segment: dt, 2 dt, ..., duration (the start sample is the previous end)."""
        return np.arange(1, max(1, round(duration_s / self.dt_s)) + 1) * self.dt_s

    def hold(self, duration_s: float, label: str = "static hold") -> None:
        bend, length = self.current
        n = len(self._time(duration_s))
        self._append(label, np.tile(bend, (n, 1)), np.full(n, length))

    def move(self, bend_deg: float, plane_deg: float, duration_s: float, free_length_mm: float | None = None,
             label: str = "move") -> None:
        """Raised-cosine transition to articulation (bend, plane) and free length."""
        start_bend, start_length = self.current
        target = math.radians(bend_deg) * np.array([math.cos(math.radians(plane_deg)),
                                                    math.sin(math.radians(plane_deg))])
        end_length = start_length if free_length_mm is None else free_length_mm
        t = self._time(duration_s)
        w = 0.5 - 0.5 * np.cos(np.pi * t / t[-1])
        self._append(label, start_bend + w[:, None] * (target - start_bend), start_length + w * (end_length - start_length))

    def sweep(self, plane_deg: float, amplitude_deg: float, frequency_hz: float, cycles: int) -> None:
        """theta = A sin(2 pi f t) in one plane, through straight to both sides (starts straight)."""
        self.move(0.0, plane_deg, 1.0)
        _, length = self.current
        t = self._time(cycles / frequency_hz)
        theta = math.radians(amplitude_deg) * np.sin(2 * np.pi * frequency_hz * t)
        direction = np.array([math.cos(math.radians(plane_deg)), math.sin(math.radians(plane_deg))])
        self._append(f"sweep plane {plane_deg:g} deg, {amplitude_deg:g} deg at {frequency_hz:g} Hz",
                     theta[:, None] * direction, np.full(len(t), length))

    def minor_loops(self, plane_deg: float, centre_deg: float, amplitude_deg: float, frequency_hz: float,
                    cycles: int) -> None:
        """Reversals: theta = centre + a sin(2 pi f t) about a bent pose."""
        self.move(centre_deg, plane_deg, 2.0)
        _, length = self.current
        t = self._time(cycles / frequency_hz)
        theta = math.radians(centre_deg) + math.radians(amplitude_deg) * np.sin(2 * np.pi * frequency_hz * t)
        direction = np.array([math.cos(math.radians(plane_deg)), math.sin(math.radians(plane_deg))])
        self._append(f"minor loops at {centre_deg:g} deg +-{amplitude_deg:g} deg", theta[:, None] * direction,
                     np.full(len(t), length))

    def circle(self, bend_deg: float, start_plane_deg: float, turns: float, period_s: float) -> None:
        """Constant articulation while the plane turns (turns > 0: counter-clockwise seen from the tip)."""
        self.move(bend_deg, start_plane_deg, 2.0)
        _, length = self.current
        t = self._time(abs(turns) * period_s)
        phi = math.radians(start_plane_deg) + math.copysign(2 * np.pi, turns) * t / period_s
        theta = math.radians(bend_deg)
        self._append(f"circle at {bend_deg:g} deg, {'ccw' if turns > 0 else 'cw'}",
                     theta * np.stack([np.cos(phi), np.sin(phi)], axis=1), np.full(len(t), length))

    def insertion_cycle(self, bend_deg: float, plane_deg: float, speed_mm_s: float, hold_s: float = 1.5) -> None:
        """At constant articulation: free length nominal -> longest -> shortest -> nominal, with holds.

        speed_mm_s is the mean speed of each change; the raised cosine peaks at pi/2 times it.
        """
        self.move(bend_deg, plane_deg, 2.0, label="move")
        low, high = self.geometry.insertion_range_mm()
        nominal = self.geometry.free_length_mm
        for target in (high, low, nominal):
            _, length = self.current
            self.move(bend_deg, plane_deg, max(1.0, abs(target - length) / speed_mm_s), target,
                      label=f"insertion change at {bend_deg:g} deg")
            self.hold(hold_s)

    def trajectory(self, name: str) -> Trajectory:
        bend = np.concatenate(self.bend)
        length = np.concatenate(self.length)
        g = self.geometry
        tendon = g.tendon_offset_mm * (bend[:, :1] * np.cos(TENDON_ANGLES_RAD) + bend[:, 1:] * np.sin(TENDON_ANGLES_RAD))
        return Trajectory(name, np.arange(len(length)) * self.dt_s, tendon + g.pretension_mm, length,
                          tuple(self.segments))


def training_trajectory(geometry: ExcitationGeometry, sample_rate_hz: float = 100.0,
                        short: bool = False) -> Trajectory:
    """The calibration/training excitation (about 230 s; `short`: one of each primitive, about 75 s)."""
    b = _Builder(geometry, sample_rate_hz)
    b.hold(3.0)
    if short:
        b.sweep(0.0, 100.0, 0.1, 1)
        b.sweep(0.0, 100.0, 0.4, 2)
        b.sweep(90.0, 70.0, 0.2, 1)
        b.minor_loops(0.0, 70.0, 20.0, 0.3, 2)
        b.hold(2.0)
        b.move(90.0, 45.0, 2.0)
        b.hold(2.0)
        b.insertion_cycle(0.0, 0.0, 6.0, hold_s=1.0)
        b.insertion_cycle(60.0, 300.0, 6.0, hold_s=1.0)
        b.circle(70.0, 0.0, 1.0, 8.0)
    else:
        for frequency_hz, cycles in ((0.05, 1), (0.2, 2), (0.5, 3)):
            b.sweep(0.0, 100.0, frequency_hz, cycles)
        b.hold(2.0)
        b.sweep(90.0, 60.0, 0.15, 2)
        b.sweep(90.0, 130.0, 0.08, 1)
        b.sweep(45.0, 90.0, 0.1, 1)
        b.sweep(135.0, 120.0, 0.3, 2)
        b.minor_loops(0.0, 80.0, 20.0, 0.25, 3)
        b.hold(2.0)
        b.minor_loops(270.0, 60.0, 15.0, 0.4, 3)
        b.hold(2.0)
        for bend_deg, plane_deg in ((120.0, 30.0), (60.0, 200.0), (0.0, 0.0)):
            b.move(bend_deg, plane_deg, 2.5)
            b.hold(3.0)
        b.insertion_cycle(0.0, 0.0, 5.0)
        b.insertion_cycle(70.0, 300.0, 5.0)
        b.circle(60.0, 0.0, 1.0, 10.0)
        b.circle(60.0, 0.0, -1.0, 10.0)
        b.circle(110.0, 90.0, 1.0, 14.0)
    b.move(0.0, 0.0, 2.0)
    b.hold(3.0)
    return b.trajectory("training (short)" if short else "training")


def holdout_trajectory(geometry: ExcitationGeometry, sample_rate_hz: float = 100.0,
                       short: bool = False) -> Trajectory:
    """The held-out excitation: other planes, amplitudes and speeds (about 130 s; `short`: about 50 s)."""
    b = _Builder(geometry, sample_rate_hz)
    b.hold(3.0)
    if short:
        b.sweep(20.0, 85.0, 0.15, 1)
        b.sweep(110.0, 110.0, 0.3, 1)
        b.minor_loops(200.0, 90.0, 25.0, 0.35, 2)
        b.hold(2.0)
        b.insertion_cycle(45.0, 160.0, 6.0, hold_s=1.0)
        b.circle(85.0, 45.0, -1.0, 8.0)
    else:
        b.sweep(20.0, 75.0, 0.07, 1)
        b.sweep(20.0, 75.0, 0.4, 2)
        b.sweep(110.0, 115.0, 0.12, 1)
        b.sweep(250.0, 95.0, 0.3, 2)
        b.minor_loops(200.0, 100.0, 25.0, 0.3, 3)
        b.hold(2.0)
        b.move(90.0, 300.0, 2.5)
        b.hold(3.0)
        b.insertion_cycle(0.0, 0.0, 6.0)
        b.insertion_cycle(50.0, 160.0, 6.0)
        b.circle(85.0, 45.0, -1.0, 9.0)
        b.circle(85.0, 45.0, 1.0, 9.0)
    b.move(0.0, 0.0, 2.0)
    b.hold(3.0)
    return b.trajectory("held-out (short)" if short else "held-out")
