"""Explicit CiA 402 sequences for a group of axes: enable, disable, change the mode of operation.

All axes of the group step together, one SYNC cycle per transition, each with its own time
limit (DriveTimeout names the axis that did not follow):

- enable: FAULT -> 0x00, 0x80 (fault reset on the rising edge of bit 7) -> SWITCH ON DISABLED
  -> 0x06 -> READY TO SWITCH ON -> 0x07 -> SWITCHED ON -> 0x0F -> OPERATION ENABLED, with halt
  (bit 8) set: nothing moves until a valid target is given;
- disable: 0x06 shutdown (power stage off, brake on), then 0x00 disable voltage;
- mode change: halt (at least one cycle, so the drive sees bit 4 low before the new mode) and
  wait until the axis stands (profile position: target reached), then write 0x6060 by SDO and
  check 0x6061; the target is set to the position actual, so a new
  cyclic synchronous position stream starts where the axis stands.
"""

from __future__ import annotations

from collections.abc import Sequence

from crest.driver import cia402
from crest.driver.cia402 import Cia402State, OperationMode
from crest.driver.cycle_runner import CycleRunner
from crest.driver.drive_axis import DriveAxis

#: Time a drive gets for one CiA 402 transition, brake release included.
STATE_CHANGE_TIMEOUT_S = 1.0
#: Extra time to come to rest after a halt, beyond max velocity / max acceleration.
HALT_MARGIN_S = 0.5


def enable(runner: CycleRunner, axes: Sequence[DriveAxis]) -> None:
    """Bring every axis to OPERATION ENABLED, halted, with the target at the position actual."""
    for axis in axes:
        axis.target_counts = axis.position_counts
        axis.halted = True

    def step(pending: list[DriveAxis]) -> None:
        for axis in pending:
            controlword = cia402.command_toward_enabled(axis.state, axis.controlword & ~cia402.HALT)
            if controlword is not None:
                axis.command(controlword)

    runner.run_until(axes, lambda axis: axis.state is Cia402State.OPERATION_ENABLED, "enable operation",
                     5 * STATE_CHANGE_TIMEOUT_S, before_cycle=step)
    for axis in axes:
        axis.must_be_enabled = True


def disable(runner: CycleRunner, axes: Sequence[DriveAxis]) -> None:
    """Shutdown, then disable voltage: every axis ends in SWITCH ON DISABLED."""
    for axis in axes:
        axis.must_be_enabled = False
        axis.command(cia402.SHUTDOWN)
    runner.run_until(axes, lambda axis: axis.state in (Cia402State.READY_TO_SWITCH_ON, Cia402State.SWITCH_ON_DISABLED),
                     "shutdown", STATE_CHANGE_TIMEOUT_S)
    for axis in axes:
        axis.command(cia402.DISABLE_VOLTAGE)
    runner.run_until(axes, lambda axis: axis.state is Cia402State.SWITCH_ON_DISABLED, "disable voltage",
                     STATE_CHANGE_TIMEOUT_S)


def switch_mode(runner: CycleRunner, axes: Sequence[DriveAxis], mode: OperationMode) -> None:
    """Halt, let each axis come to rest, select ``mode`` and point the target at where it stands."""
    changing = [axis for axis in axes if axis.mode is not mode]
    if not changing:
        return
    for axis in changing:
        axis.command(cia402.ENABLE_OPERATION, halt=True)

    def standing(axis: DriveAxis) -> bool:
        """Profile position shows the end of the halt ramp in bit 10; the other modes stand already."""
        return axis.mode is not OperationMode.PROFILE_POSITION or axis.has_status(cia402.TARGET_REACHED)

    runner.run_until(changing, standing, "halt before mode change",
                     {axis.name: axis.config.max_velocity_mm_s / axis.config.max_acceleration_mm_s2 + HALT_MARGIN_S
                      for axis in changing})
    for axis in changing:
        axis.target_counts = axis.position_counts
        axis.set_mode(mode)
        runner.raise_if_stopped()
