"""Profile position mode (CiA 402-2, mode 1): set-points through the controlword handshake.

Controlword bits of this mode:
    bit 4  new set-point        a rising edge hands 0x607A to the drive
    bit 5  change set immediately  1: the new set-point replaces the running one;
                                   0: it is buffered and runs after the current one
    bit 6  abs / rel            1: 0x607A is relative to the preceding target
    bit 8  halt                 1: stop with the profile deceleration 0x6084, keep the target

Statusword bits of this mode:
    bit 10 target reached       the profile has ended (or halted) and the actual
                                position has stayed within the position window
                                0x6067 for the position window time 0x6068
    bit 12 set-point acknowledge  1 after a set-point was taken; it drops when
                                bit 4 is cleared and the buffer can take another one
    bit 13 following error      set by the drive's following-error monitor

Handshake: master sets bit 4 -> drive sets bit 12 -> master clears bit 4 ->
drive clears bit 12 (as soon as its one-deep buffer is free).
"""

from __future__ import annotations

from dataclasses import dataclass

from sim_backend.drive.setpoint_generator import SetpointGenerator

NEW_SET_POINT_BIT = 0x0010
CHANGE_SET_IMMEDIATELY_BIT = 0x0020
RELATIVE_BIT = 0x0040
HALT_BIT = 0x0100

TARGET_REACHED_BIT = 0x0400
SET_POINT_ACKNOWLEDGE_BIT = 0x1000


@dataclass(frozen=True)
class MotionProfile:
    """Profile limits in counts: 0x6081 velocity, 0x6083 acceleration, 0x6084 deceleration."""

    velocity_counts_s: float
    acceleration_counts_s2: float
    deceleration_counts_s2: float


class ProfilePosition:
    """The set-point buffer and handshake of profile position mode (positions in counts)."""

    def __init__(self) -> None:
        self._new_set_point_bit = False
        self.reset(0.0)

    def reset(self, reference_counts: float) -> None:
        """Forget all set-points; relative moves start from ``reference_counts``."""
        self.active_target_counts: float | None = None
        self.pending_target_counts: float | None = None
        self.last_target_counts = reference_counts
        self.acknowledged = False
        self.halted = False

    def on_controlword(self, controlword: int) -> bool:
        """Record the mode bits; True when a rising edge of bit 4 asks to take a set-point."""
        bit4 = bool(controlword & NEW_SET_POINT_BIT)
        rising = bit4 and not self._new_set_point_bit
        self._new_set_point_bit = bit4
        self.halted = bool(controlword & HALT_BIT)
        if not bit4 and self.pending_target_counts is None:
            self.acknowledged = False
        return rising and self.pending_target_counts is None

    def accept(self, target_counts: float, controlword: int) -> None:
        """Take a set-point and acknowledge it (bit 12).

        The drive resolves bit 6 first: a relative 0x607A is added to
        ``last_target_counts``. ``target_counts`` is absolute and already limited.
        """
        if self.active_target_counts is None or controlword & CHANGE_SET_IMMEDIATELY_BIT:
            self.active_target_counts = target_counts
        else:
            self.pending_target_counts = target_counts
        self.last_target_counts = target_counts
        self.acknowledged = True

    def step(self, demand: SetpointGenerator, profile: MotionProfile, dt_s: float) -> None:
        """One cycle of the profile toward the active target, or of the halt ramp."""
        if self.halted:
            demand.run_at(0.0, profile.deceleration_counts_s2, dt_s)
            return
        if self.active_target_counts is None:
            demand.run_at(0.0, profile.deceleration_counts_s2, dt_s)
            return
        arrived = demand.move_toward(self.active_target_counts, profile.velocity_counts_s,
                                     profile.acceleration_counts_s2, profile.deceleration_counts_s2, dt_s)
        if arrived:
            self.active_target_counts = self.pending_target_counts
            self.pending_target_counts = None
            if not self._new_set_point_bit:
                self.acknowledged = False

    def statusword_bits(self, demand: SetpointGenerator, settled: bool) -> int:
        """Bits 10 (target reached) and 12 (set-point acknowledge); ``settled``: in the window long enough."""
        profile_done = demand.is_stopped and (self.halted or self.active_target_counts is None)
        bits = TARGET_REACHED_BIT if profile_done and settled else 0
        if self.acknowledged:
            bits |= SET_POINT_ACKNOWLEDGE_BIT
        return bits
