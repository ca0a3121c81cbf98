"""Homing mode (CiA 402-2, mode 6): finding the reference position.

Methods supported (0x6098):
    35, 37  homing on the current position: the position actual value becomes the
            home offset 0x607C at once (37 is the newer number for 35).
    17      homing on the negative limit switch: run negative at the switch-search
            speed 0x6099:1 until the switch closes, then positive at the zero-search
            speed 0x6099:2 until it opens; that edge is the home position, where the
            position actual value becomes the home offset 0x607C. Ramps use the
            homing acceleration 0x609A.

Controlword: bit 4 rising edge starts homing, bit 8 halt interrupts it.
Statusword (bit 13, 12, 10):
    0 0 0  homing in progress
    0 0 1  homing interrupted or not started
    0 1 1  homing attained, target reached
    1 0 1  homing error, velocity is zero (e.g. no limit switch wired)
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from sim_backend.drive.setpoint_generator import SetpointGenerator

START_BIT = 0x0010
HALT_BIT = 0x0100

TARGET_REACHED_BIT = 0x0400
HOMING_ATTAINED_BIT = 0x1000
HOMING_ERROR_BIT = 0x2000

CURRENT_POSITION_METHODS = frozenset({35, 37})
NEGATIVE_LIMIT_SWITCH_METHOD = 17
SUPPORTED_METHODS = CURRENT_POSITION_METHODS | {NEGATIVE_LIMIT_SWITCH_METHOD}


class HomingPhase(enum.Enum):
    IDLE = "not started or interrupted"
    SEARCH_SWITCH = "searching the switch"
    SEARCH_ZERO = "leaving the switch"
    STOPPING = "stopping after the home edge"
    ATTAINED = "attained"
    ERROR = "error"


@dataclass(frozen=True)
class HomingParameters:
    """Homing objects in counts: 0x6098 method, 0x607C offset, 0x6099 speeds, 0x609A acceleration."""

    method: int
    home_offset_counts: int
    switch_search_speed_counts_s: float
    zero_search_speed_counts_s: float
    acceleration_counts_s2: float


class Homing:
    """Homing procedure of one axis.

    ``negative_limit_switch_counts`` is where the simulated switch sits in the
    motor's own (physical) position; None means no switch is wired.
    The switch is closed while the motor is at or below that position.
    """

    def __init__(self, negative_limit_switch_counts: float | None) -> None:
        self.negative_limit_switch_counts = negative_limit_switch_counts
        self.phase = HomingPhase.IDLE
        self._start_bit = False

    def interrupt(self) -> None:
        """Operation disabled or mode left: a running search stops; a result is kept."""
        if self.phase in (HomingPhase.SEARCH_SWITCH, HomingPhase.SEARCH_ZERO, HomingPhase.STOPPING):
            self.phase = HomingPhase.IDLE

    def on_controlword(self, controlword: int) -> bool:
        """True on the rising edge of bit 4 (start homing)."""
        bit4 = bool(controlword & START_BIT)
        rising = bit4 and not self._start_bit
        self._start_bit = bit4
        return rising

    def start(self, parameters: HomingParameters, actual_counts: float) -> float | None:
        """Begin the procedure; returns the new position offset (counts) if homing completed at once.

        The position offset is what the drive adds to its motor position to report
        the position actual value: offset = home offset - motor position at home.
        """
        if parameters.method in CURRENT_POSITION_METHODS:
            self.phase = HomingPhase.ATTAINED
            return parameters.home_offset_counts - actual_counts
        if self.negative_limit_switch_counts is None:
            self.phase = HomingPhase.ERROR
            return None
        self.phase = HomingPhase.SEARCH_SWITCH
        return None

    def step(self, demand: SetpointGenerator, actual_counts: float, halted: bool,
             parameters: HomingParameters, dt_s: float) -> float | None:
        """One cycle of the search; returns the new position offset when the home edge is passed."""
        if self.phase in (HomingPhase.IDLE, HomingPhase.ATTAINED, HomingPhase.ERROR):
            demand.run_at(0.0, parameters.acceleration_counts_s2, dt_s)
            return None
        if halted:
            self.phase = HomingPhase.IDLE
            demand.run_at(0.0, parameters.acceleration_counts_s2, dt_s)
            return None
        switch_closed = actual_counts <= self.negative_limit_switch_counts
        if self.phase is HomingPhase.SEARCH_SWITCH:
            if switch_closed:
                self.phase = HomingPhase.SEARCH_ZERO
            else:
                demand.run_at(-parameters.switch_search_speed_counts_s, parameters.acceleration_counts_s2, dt_s)
                return None
        if self.phase is HomingPhase.SEARCH_ZERO:
            if switch_closed:
                demand.run_at(parameters.zero_search_speed_counts_s, parameters.acceleration_counts_s2, dt_s)
                return None
            # The switch opened during the last cycle: the drive latches the edge itself.
            self.phase = HomingPhase.STOPPING
            demand.run_at(0.0, parameters.acceleration_counts_s2, dt_s)
            return parameters.home_offset_counts - self.negative_limit_switch_counts
        demand.run_at(0.0, parameters.acceleration_counts_s2, dt_s)
        if demand.is_stopped:
            self.phase = HomingPhase.ATTAINED
        return None

    def statusword_bits(self, demand: SetpointGenerator) -> int:
        """Bits 10, 12 and 13 as in the module docstring."""
        if self.phase is HomingPhase.ATTAINED:
            return HOMING_ATTAINED_BIT | TARGET_REACHED_BIT
        if self.phase is HomingPhase.ERROR:
            return HOMING_ERROR_BIT | (TARGET_REACHED_BIT if demand.is_stopped else 0)
        if self.phase is HomingPhase.IDLE:
            return TARGET_REACHED_BIT
        return 0
