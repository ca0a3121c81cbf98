"""Profile position (CiA 402 mode 1): set-points handed over with the handshake of bits 4 and 12.

    host:  0x607A = target, one cycle ahead (a drive may act on the controlword of an RPDO
           before it has stored the target mapped after it)
    host:  controlword bit 4 (new set-point) 0 -> 1
    drive: statusword bit 12 (set-point acknowledge) 0 -> 1: the set-point is taken
    host:  bit 4 -> 0
    drive: bit 12 -> 0: the drive can take the next set-point
    drive: bit 10 (target reached) once the profile has ended within the position window

Bit 5 (change set immediately) is set, so a new set-point replaces a running one: a jog key
held down moves the target on without waiting. Profile velocity 0x6081 and acceleration /
deceleration 0x6083 / 0x6084 are written by SDO before the set-point when they change.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from crest.driver import cia402
from crest.driver.cycle_runner import CycleRunner
from crest.driver.drive_axis import DriveAxis
from crest.driver.synchronized_move import AxisProfile

PROFILE_VELOCITY = 0x6081
PROFILE_ACCELERATION = 0x6083
PROFILE_DECELERATION = 0x6084
#: Time a drive gets for each half of the handshake.
HANDSHAKE_TIMEOUT_S = 0.5
#: Extra time for a move beyond its planned duration (settling into the position window).
SETTLE_MARGIN_S = 1.0


def set_profile(axis: DriveAxis, profile: AxisProfile) -> None:
    """Write 0x6081, 0x6083, 0x6084 (counts, at least 1) if they differ from the last ones written."""
    velocity = max(1, round(profile.velocity_mm_s * axis.config.counts_per_mm))
    acceleration = max(1, round(profile.acceleration_mm_s2 * axis.config.counts_per_mm))
    if axis.profile_counts == (velocity, acceleration):
        return
    axis.sdo.write(PROFILE_VELOCITY, 0, velocity, "set profile velocity")
    axis.sdo.write(PROFILE_ACCELERATION, 0, acceleration, "set profile acceleration")
    axis.sdo.write(PROFILE_DECELERATION, 0, acceleration, "set profile deceleration")
    axis.profile_counts = (velocity, acceleration)


def hand_over(runner: CycleRunner, targets_counts: Mapping[str, int], axes: Sequence[DriveAxis]) -> None:
    """Give each axis in ``targets_counts`` its new set-point with the handshake; halt is released."""
    moving = [axis for axis in axes if axis.name in targets_counts]
    for axis in moving:
        axis.target_counts = targets_counts[axis.name]
    runner.cycle()  # 0x607A is in the drive before bit 4 rises
    for axis in moving:
        axis.command(cia402.ENABLE_OPERATION | cia402.NEW_SET_POINT | cia402.CHANGE_SET_IMMEDIATELY, halt=False)
    runner.run_until(moving, lambda axis: axis.has_status(cia402.SET_POINT_ACKNOWLEDGE),
                     "profile position: set-point acknowledge", HANDSHAKE_TIMEOUT_S)
    for axis in moving:
        axis.command(cia402.ENABLE_OPERATION | cia402.CHANGE_SET_IMMEDIATELY)
    runner.run_until(moving, lambda axis: not axis.statusword & cia402.SET_POINT_ACKNOWLEDGE,
                     "profile position: set-point acknowledge released", HANDSHAKE_TIMEOUT_S)


def wait_reached(runner: CycleRunner, axes: Sequence[DriveAxis], duration_s: float) -> None:
    """Cycle until every axis reports target reached (bit 10)."""
    runner.run_until(axes, lambda axis: axis.has_status(cia402.TARGET_REACHED), "profile position: target reached",
                     duration_s + SETTLE_MARGIN_S)
