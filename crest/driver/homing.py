"""Homing (CiA 402 mode 6) of a group of axes at once.

Each axis runs its configured method (0x6098, written at boot): 35/37 make the current
position the home position at once; 17 runs to the negative limit switch and back off it.
Controlword bit 4 (rising edge) starts homing, halt cleared. Statusword in homing mode:
bit 12 homing attained, bit 10 target reached, bit 13 homing error. After homing the position
actual equals the home offset 0x607C (home_position_mm) at the home position.
"""

from __future__ import annotations

from collections.abc import Sequence

from crest.driver import cia402
from crest.driver.cia402 import OperationMode
from crest.driver.cycle_runner import CycleRunner
from crest.driver.drive_axis import DriveAxis
from crest.driver.drive_parameters import HOMING_SWITCH_SPEED_FRACTION
from crest.driver.errors import HomingFailed
from crest.driver.state_control import STATE_CHANGE_TIMEOUT_S, switch_mode

CURRENT_POSITION_METHODS = frozenset({35, 37})


def homing_timeout_s(axis: DriveAxis) -> float:
    """Time limit: an immediate method gets one state-change time; a switch search gets twice the
    time to cross the whole soft range at the switch-search speed (the back-off from the switch
    at the slower zero-search speed is short), plus one state-change time."""
    config = axis.config
    if config.homing_method in CURRENT_POSITION_METHODS:
        return STATE_CHANGE_TIMEOUT_S
    span_mm = config.soft_max_mm - config.soft_min_mm
    return 2.0 * span_mm / (HOMING_SWITCH_SPEED_FRACTION * config.max_velocity_mm_s) + STATE_CHANGE_TIMEOUT_S


def _homing_error(axis: DriveAxis) -> HomingFailed | None:
    if axis.statusword & cia402.HOMING_ERROR:
        return HomingFailed(axis.name, f"homing method {axis.config.homing_method} reported a homing error "
                                       f"(statusword 0x{axis.statusword:04X}); check the reference switch of the "
                                       "axis and homing_method in the configuration")
    return None


def home(runner: CycleRunner, axes: Sequence[DriveAxis]) -> None:
    """Home every axis (enabled beforehand); they end halted in profile position mode."""
    switch_mode(runner, axes, OperationMode.HOMING)
    for axis in axes:
        axis.command(cia402.ENABLE_OPERATION | cia402.NEW_SET_POINT, halt=False)
    runner.run_until(axes, lambda axis: axis.has_status(cia402.HOMING_ATTAINED | cia402.TARGET_REACHED), "homing",
                     {axis.name: homing_timeout_s(axis) for axis in axes}, failed=_homing_error)
    for axis in axes:
        axis.command(cia402.ENABLE_OPERATION, halt=True)
    switch_mode(runner, axes, OperationMode.PROFILE_POSITION)
