"""Excitation trajectories for calibration and gap diagnosis (`crest excite`).

Each is a `control.trajectories.Trajectory`: set-points in articulation coordinates, the bend
vector b = theta * (cos phi, sin phi) [rad] of the whole catheter and the free length L [mm],
checked against the workspace and the motion limits before anything runs. The testbed follows
them with the constant-curvature inverse (`Trajectory.tendon_mm`):

    u_k = r * (b_x cos phi_k + b_y sin phi_k) + pretension,   phi_k = (k - 1) * 90 deg.

The primitives each expose one effect's signature:
- planar sweeps through straight at several amplitudes and speeds (rate dependence,
  tension-dependent losses, torsion in each plane);
- reversals with minor loops (dead band after reversal: backlash, Dahl stiffness);
- insertion changes at constant articulation, straight and bent (tube friction, gravity,
  precurvature, which all scale with free length);
- circles in both directions (out-of-plane coupling, direction dependence);
- static holds (bias at rest: tracker offset, gravity; rate effects vanish there).
Every primitive starts and ends at rest: moves are trapezoids within the limits, sweeps and
minor loops are cosines theta = c + a cos(2 pi f t) that begin at a turning point, and circles
turn their plane on a trapezoid. So the drives can follow the set-points as they are (no
slowing down), and decimating them for fitting loses no reversal.
Training and held-out trajectories use different planes, amplitudes and speeds.

The model starts every recording from the straight state with no friction stored along the
catheter. A catheter that has moved before stores friction (hysteresis) even when straight, so
each excitation is preceded, unrecorded, by `conditioning_trajectory`: a spiral in bend space
whose articulation decays to zero, which erases the friction memory the way a decaying
alternating field demagnetises iron. The decay is exponential, not linear: each friction element
keeps a memory of about the articulation lost in the last turn before its motion stops saturating
it, and an exponential decay loses ever less per turn as the spiral closes in. In the model a
catheter run through the training excitation and then the spiral starts the held-out excitation
within 0.01 mm of a fresh one (0.4 mm with a linear decay over the same ten turns, which showed in
every log as a constant tip offset over its first hold; without the spiral, 0.5 mm RMS and 1.4 mm
in its first 10 s).
"""
from __future__ import annotations

import math

import numpy as np

from control.motion_limits import MotionLimits
from control.trajectories import Trajectory
from control.trajectories.path_builder import PathBuilder
from control.trajectories.trapezoid import trapezoid_samples
from control.workspace import Workspace

CONDITIONING_DEG = 100.0         # the spiral's first articulation ...
CONDITIONING_TURNS = 10          # ... decaying to zero over this many turns ...
CONDITIONING_PERIOD_S = 3.0      # ... of this period ...
CONDITIONING_DECAY = 5.0         # ... as exp(-CONDITIONING_DECAY t / duration), shifted to end at zero
MOVE_VELOCITY_RAD_S = 1.2        # articulation moves between primitives
MOVE_ACCELERATION_RAD_S2 = 2.0
INSERTION_ACCELERATION_MM_S2 = 20.0
STEP_SHARE = 0.9                 # steps of the fast-input excitation: this share of the tendon axes' limits
MULTISINE_RAMP_S = 1.5           # raised-cosine fade in and out of each multisine


def _direction(plane_deg: float) -> np.ndarray:
    return np.array([math.cos(math.radians(plane_deg)), math.sin(math.radians(plane_deg))])


class _Excitation:
    """Appends the excitation primitives to a PathBuilder, each starting where the last ended."""

    def __init__(self, workspace: Workspace, limits: MotionLimits, period_s: float):
        self.workspace = workspace
        self.path = PathBuilder(workspace, limits, period_s, workspace.home)

    def _times(self, duration_s: float) -> np.ndarray:
        """T, 2T, ..., duration_s: the samples of a primitive after its start."""
        period = self.path.period_s
        return period * np.arange(1, max(1, round(duration_s / period)) + 1)

    def hold(self, duration_s: float) -> None:
        self.path.hold(duration_s, "static hold")

    def move(self, bend_deg: float, plane_deg: float, free_length_mm: float | None = None,
             label: str = "move", insertion_velocity_mm_s: float | None = None) -> None:
        """A trapezoidal move to articulation (bend, plane) and free length (default: unchanged)."""
        length = self.path.insertion_mm if free_length_mm is None else free_length_mm
        self.path.line(math.radians(bend_deg) * _direction(plane_deg), length, label,
                       bend_velocity_rad_s=MOVE_VELOCITY_RAD_S, bend_acceleration_rad_s2=MOVE_ACCELERATION_RAD_S2,
                       insertion_velocity_mm_s=insertion_velocity_mm_s,
                       insertion_acceleration_mm_s2=INSERTION_ACCELERATION_MM_S2)

    def _oscillate(self, label: str, plane_deg: float, centre_deg: float, amplitude_deg: float,
                   frequency_hz: float, cycles: int) -> None:
        """theta = centre + amplitude cos(2 pi f t) in one plane, from its turning point centre + amplitude."""
        self.move(centre_deg + amplitude_deg, plane_deg)
        t = self._times(cycles / frequency_hz)
        theta = math.radians(centre_deg) + math.radians(amplitude_deg) * np.cos(2 * np.pi * frequency_hz * t)
        self.path.samples(theta[:, None] * _direction(plane_deg), np.full(len(t), self.path.insertion_mm), label)

    def sweep(self, plane_deg: float, amplitude_deg: float, frequency_hz: float, cycles: int) -> None:
        """Through straight to both sides: theta = A cos(2 pi f t) in one plane."""
        self._oscillate(f"sweep plane {plane_deg:g} deg, {amplitude_deg:g} deg at {frequency_hz:g} Hz", plane_deg,
                        0.0, amplitude_deg, frequency_hz, cycles)

    def minor_loops(self, plane_deg: float, centre_deg: float, amplitude_deg: float, frequency_hz: float,
                    cycles: int) -> None:
        """Reversals about a bent pose: theta = centre + a cos(2 pi f t)."""
        self._oscillate(f"minor loops at {centre_deg:g} deg +-{amplitude_deg:g} deg", plane_deg, centre_deg,
                        amplitude_deg, frequency_hz, cycles)

    def circle(self, bend_deg: float, start_plane_deg: float, turns: float, period_s: float) -> None:
        """Constant articulation while the plane turns (turns > 0: counter-clockwise seen from the tip).

        The plane angle runs on a trapezoid up to omega = 2 pi / period_s with acceleration
        omega^2 / pi (a quarter turn to reach full speed), as `control.trajectories.circle`.
        """
        self.move(bend_deg, start_plane_deg)
        omega = 2 * np.pi / period_s
        turned = trapezoid_samples(2 * np.pi * abs(turns), omega, omega ** 2 / np.pi, self.path.period_s)
        phi = math.radians(start_plane_deg) + math.copysign(1.0, turns) * turned
        self.path.samples(math.radians(bend_deg) * np.column_stack([np.cos(phi), np.sin(phi)]),
                          np.full(len(phi), self.path.insertion_mm),
                          f"circle at {bend_deg:g} deg, {'ccw' if turns > 0 else 'cw'}")

    def step(self, bend_deg: float, plane_deg: float, hold_s: float) -> None:
        """A step: the fastest move the tendon axes allow (STEP_SHARE of their speed and acceleration
        limits, as bend rates: |b'| <= v_max / r), then a hold that shows the transient settle."""
        r = self.workspace.tendon_offset_mm
        limits = self.path.limits
        self.path.line(math.radians(bend_deg) * _direction(plane_deg), self.path.insertion_mm,
                       f"step to {bend_deg:g} deg in plane {plane_deg:g} deg",
                       bend_velocity_rad_s=STEP_SHARE * limits.tendon_velocity_mm_s / r,
                       bend_acceleration_rad_s2=STEP_SHARE * limits.tendon_acceleration_mm_s2 / r)
        self.hold(hold_s)

    def multisine(self, plane_deg: float, centre_deg: float, tones: tuple[tuple[float, float, float], ...],
                  duration_s: float) -> None:
        """theta = c + w(t) sum_i a_i sin(2 pi f_i t + phi_i) in one plane, tones = ((a_i [deg], f_i [Hz],
        phi_i [rad]), ...), after a move to c. The window w rises and falls as a raised cosine over
        MULTISINE_RAMP_S at each end, so the multisine starts and ends at rest at c."""
        self.move(centre_deg, plane_deg)
        t = self._times(duration_s)
        ramp = np.clip(np.minimum(t, duration_s - t) / MULTISINE_RAMP_S, 0.0, 1.0)
        window = 0.5 * (1.0 - np.cos(np.pi * ramp))
        theta_deg = centre_deg + window * sum(a * np.sin(2 * np.pi * f * t + phase) for a, f, phase in tones)
        self.path.samples(np.radians(theta_deg)[:, None] * _direction(plane_deg),
                          np.full(len(t), self.path.insertion_mm),
                          f"multisine plane {plane_deg:g} deg about {centre_deg:g} deg")

    def insertion_cycle(self, bend_deg: float, plane_deg: float, speed_mm_s: float, hold_s: float = 1.5) -> None:
        """At constant articulation: free length nominal -> longest -> shortest -> nominal, with holds.

        The free-length excursion is 30 % below to 15 % above nominal (inside the workspace);
        speed_mm_s is the peak speed of each change.
        """
        self.move(bend_deg, plane_deg)
        nominal = self.workspace.home_insertion_mm
        low = max(self.workspace.min_insertion_mm, 0.7 * nominal)
        high = min(self.workspace.max_insertion_mm, 1.15 * nominal)
        for target in (high, low, nominal):
            self.move(bend_deg, plane_deg, target, label=f"insertion change at {bend_deg:g} deg",
                      insertion_velocity_mm_s=speed_mm_s)
            self.hold(hold_s)

    def trajectory(self) -> Trajectory:
        self.move(0.0, 0.0)
        self.hold(3.0)
        return self.path.build()


def conditioning_trajectory(workspace: Workspace, limits: MotionLimits = MotionLimits(),
                            period_s: float = 0.01) -> Trajectory:
    """The friction-erasing spiral (see module doc) from straight at the home free length, back to it.

    b(t) = theta(t) (cos psi, sin psi), psi = 2 pi t / P, with D = n P and decay rate k,

        theta = A min(1, t/P) (exp(-k t/D) - exp(-k)) / (1 - exp(-k)):

    the articulation ramps in over the first turn and decays exponentially, reaching zero at D.
    """
    path = PathBuilder(workspace, limits, period_s, workspace.home)
    duration_s = CONDITIONING_TURNS * CONDITIONING_PERIOD_S
    t = period_s * np.arange(1, round(duration_s / period_s) + 1)
    floor = math.exp(-CONDITIONING_DECAY)
    decay = (np.exp(-CONDITIONING_DECAY * t / duration_s) - floor) / (1.0 - floor)
    theta = math.radians(CONDITIONING_DEG) * np.minimum(1.0, t / CONDITIONING_PERIOD_S) * decay
    psi = 2 * np.pi * t / CONDITIONING_PERIOD_S
    path.samples(theta[:, None] * np.column_stack([np.cos(psi), np.sin(psi)]), np.full(len(t), path.insertion_mm),
                 "conditioning spiral")
    path.hold(1.0, "static hold")
    return path.build()


def training_trajectory(workspace: Workspace, limits: MotionLimits = MotionLimits(), period_s: float = 0.01,
                        short: bool = False) -> Trajectory:
    """The calibration/training excitation from straight at the home free length (about 250 s;
    `short`: one of each primitive, about 90 s), sampled every period_s."""
    b = _Excitation(workspace, limits, period_s)
    b.hold(3.0)
    if short:
        b.sweep(0.0, 100.0, 0.1, 1)
        b.sweep(0.0, 100.0, 0.4, 2)
        b.sweep(90.0, 70.0, 0.2, 1)
        b.minor_loops(0.0, 70.0, 20.0, 0.3, 2)
        b.hold(2.0)
        b.move(90.0, 45.0)
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
            b.move(bend_deg, plane_deg)
            b.hold(3.0)
        b.insertion_cycle(0.0, 0.0, 5.0)
        b.insertion_cycle(70.0, 300.0, 5.0)
        b.circle(60.0, 0.0, 1.0, 10.0)
        b.circle(60.0, 0.0, -1.0, 10.0)
        b.circle(110.0, 90.0, 1.0, 14.0)
    return b.trajectory()


def holdout_trajectory(workspace: Workspace, limits: MotionLimits = MotionLimits(), period_s: float = 0.01,
                       short: bool = False) -> Trajectory:
    """The held-out excitation: other planes, amplitudes and speeds (about 140 s; `short`: about 60 s)."""
    b = _Excitation(workspace, limits, period_s)
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
        b.move(90.0, 300.0)
        b.hold(3.0)
        b.insertion_cycle(0.0, 0.0, 6.0)
        b.insertion_cycle(50.0, 160.0, 6.0)
        b.circle(85.0, 45.0, -1.0, 9.0)
        b.circle(85.0, 45.0, 1.0, 9.0)
    return b.trajectory()


def fast_input_trajectories(workspace: Workspace, limits: MotionLimits = MotionLimits(),
                            period_s: float = 0.01) -> dict[str, Trajectory]:
    """The fast-input excitation for the dynamic mode (`crest excite --fast-inputs`): "train" and
    "holdout" (about 53 s and 33 s), each steps at the tendon axes' limits with holds, and
    multisines of three tones pulling the tendons at up to about 16 mm/s (the peak rate of
    r*theta, r*sum a_i 2 pi f_i) in other planes, amplitudes, frequencies and phases for each.
    At these speeds the catheter's damping and mass show (model.gap.calibration.is_fast)."""
    logs = {}
    for name, (step_planes, steps_deg, sine_planes, centre_deg, tones) in {
        "train": ((0.0, 90.0), (60.0, 120.0, 30.0, 0.0), (0.0, 90.0), 50.0,
                  ((35.0, 0.4, 0.0), (18.0, 1.1, 1.3), (9.0, 2.7, 2.9))),
        "holdout": ((180.0, 270.0), (90.0, 40.0, 0.0), (270.0,), 45.0,
                    ((30.0, 0.5, 0.7), (16.0, 1.4, 2.1), (8.0, 2.3, 0.4))),
    }.items():
        b = _Excitation(workspace, limits, period_s)
        b.hold(2.0)
        for plane_deg in step_planes:
            for bend_deg in steps_deg:
                b.step(bend_deg, plane_deg, hold_s=1.5)
        for plane_deg in sine_planes:
            b.multisine(plane_deg, centre_deg, tones, duration_s=15.0)
        logs[name] = b.trajectory()
    return logs
