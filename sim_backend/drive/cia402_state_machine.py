"""The CiA 402 drive state machine (IEC 61800-7-201 / CiA 402-2, "PDS FSA").

The controlword 0x6040 selects a device control command from bits 0-3 and 7
(x = don't care):

    command                     bit 7  3  2  1  0
    shutdown                        0  x  1  1  0
    switch on / disable operation   0  0  1  1  1
    switch on + enable operation    0  1  1  1  1
    disable voltage                 0  x  x  0  x
    quick stop                      0  x  0  1  x
    fault reset                   0->1 x  x  x  x   (rising edge only)

The statusword 0x6041 shows the state in bits 0-3, 5 and 6 (x = don't care):

    state                    mask  value   bits 6 5 3 2 1 0
    not ready to switch on   0x4F  0x00         0 x 0 0 0 0
    switch on disabled       0x4F  0x40         1 x 0 0 0 0
    ready to switch on       0x6F  0x21         0 1 0 0 0 1
    switched on              0x6F  0x23         0 1 0 0 1 1
    operation enabled        0x6F  0x27         0 1 0 1 1 1
    quick stop active        0x6F  0x07         0 0 0 1 1 1
    fault reaction active    0x4F  0x0F         0 x 1 1 1 1
    fault                    0x4F  0x08         0 x 1 0 0 0

Bit 4 (voltage enabled) is set while the power stage has voltage applied.

This module holds no time, motion or CAN: it only says which transition a
command causes. The drive performs the motion that goes with it.
"""

from __future__ import annotations

import enum


class DriveState(enum.Enum):
    """A CiA 402 state; ``value`` is its statusword bits 0-6."""

    NOT_READY_TO_SWITCH_ON = 0x00
    SWITCH_ON_DISABLED = 0x40
    READY_TO_SWITCH_ON = 0x31
    SWITCHED_ON = 0x33
    OPERATION_ENABLED = 0x37
    QUICK_STOP_ACTIVE = 0x17
    FAULT_REACTION_ACTIVE = 0x1F
    FAULT = 0x08

    @property
    def statusword_bits(self) -> int:
        """Statusword bits 0-6 (ready, switched on, enabled, fault, voltage, quick stop, disabled)."""
        return self.value


#: Statusword (mask, value) that identifies each state, CiA 402-2 table "statusword".
STATUSWORD_MASKS: dict[DriveState, tuple[int, int]] = {
    DriveState.NOT_READY_TO_SWITCH_ON: (0x4F, 0x00),
    DriveState.SWITCH_ON_DISABLED: (0x4F, 0x40),
    DriveState.READY_TO_SWITCH_ON: (0x6F, 0x21),
    DriveState.SWITCHED_ON: (0x6F, 0x23),
    DriveState.OPERATION_ENABLED: (0x6F, 0x27),
    DriveState.QUICK_STOP_ACTIVE: (0x6F, 0x07),
    DriveState.FAULT_REACTION_ACTIVE: (0x4F, 0x0F),
    DriveState.FAULT: (0x4F, 0x08),
}


def state_from_statusword(statusword: int) -> DriveState:
    """Decode the state shown by a statusword (the inverse of ``DriveState.statusword_bits``)."""
    for state, (mask, value) in STATUSWORD_MASKS.items():
        if statusword & mask == value:
            return state
    raise ValueError(f"statusword 0x{statusword:04X} shows no CiA 402 state")


class Command(enum.Enum):
    """A device control command decoded from controlword bits 0-3 (bit 7 clear)."""

    SHUTDOWN = "shutdown"
    SWITCH_ON = "switch on"  # also "disable operation" when operation is enabled
    ENABLE_OPERATION = "switch on + enable operation"
    DISABLE_VOLTAGE = "disable voltage"
    QUICK_STOP = "quick stop"


FAULT_RESET_BIT = 0x0080


def decode_command(controlword: int) -> Command | None:
    """The command of a controlword, or None when bit 7 (fault reset) is set.

    Disable voltage (bit 1 clear) takes precedence over quick stop (bit 2 clear),
    which takes precedence over shutdown, as the table in the module docstring reads.
    """
    if controlword & FAULT_RESET_BIT:
        return None
    if controlword & 0x02 == 0:
        return Command.DISABLE_VOLTAGE
    if controlword & 0x04 == 0:
        return Command.QUICK_STOP
    if controlword & 0x01 == 0:
        return Command.SHUTDOWN
    if controlword & 0x08 == 0:
        return Command.SWITCH_ON
    return Command.ENABLE_OPERATION


S = DriveState
C = Command
#: (state, command) -> (transition numbers, new state), CiA 402-2 figure "PDS FSA".
TRANSITIONS: dict[tuple[DriveState, Command], tuple[tuple[int, ...], DriveState]] = {
    (S.SWITCH_ON_DISABLED, C.SHUTDOWN): ((2,), S.READY_TO_SWITCH_ON),
    (S.READY_TO_SWITCH_ON, C.SWITCH_ON): ((3,), S.SWITCHED_ON),
    (S.READY_TO_SWITCH_ON, C.ENABLE_OPERATION): ((3, 4), S.OPERATION_ENABLED),
    (S.SWITCHED_ON, C.ENABLE_OPERATION): ((4,), S.OPERATION_ENABLED),
    (S.OPERATION_ENABLED, C.SWITCH_ON): ((5,), S.SWITCHED_ON),
    (S.SWITCHED_ON, C.SHUTDOWN): ((6,), S.READY_TO_SWITCH_ON),
    (S.READY_TO_SWITCH_ON, C.DISABLE_VOLTAGE): ((7,), S.SWITCH_ON_DISABLED),
    (S.READY_TO_SWITCH_ON, C.QUICK_STOP): ((7,), S.SWITCH_ON_DISABLED),
    (S.OPERATION_ENABLED, C.SHUTDOWN): ((8,), S.READY_TO_SWITCH_ON),
    (S.OPERATION_ENABLED, C.DISABLE_VOLTAGE): ((9,), S.SWITCH_ON_DISABLED),
    (S.SWITCHED_ON, C.DISABLE_VOLTAGE): ((10,), S.SWITCH_ON_DISABLED),
    (S.SWITCHED_ON, C.QUICK_STOP): ((10,), S.SWITCH_ON_DISABLED),
    (S.OPERATION_ENABLED, C.QUICK_STOP): ((11,), S.QUICK_STOP_ACTIVE),
    (S.QUICK_STOP_ACTIVE, C.DISABLE_VOLTAGE): ((12,), S.SWITCH_ON_DISABLED),
    (S.QUICK_STOP_ACTIVE, C.ENABLE_OPERATION): ((16,), S.OPERATION_ENABLED),
}
del S, C

#: Quick stop option codes (0x605A) that stay in QUICK STOP ACTIVE after the stop,
#: so that transition 16 (enable operation) is possible.
QUICK_STOP_HOLD_OPTIONS = frozenset({5, 6, 7, 8})


class Cia402StateMachine:
    """The drive's current CiA 402 state and the controlword edge it needs.

    Each method returns the CiA 402 transition numbers it took (empty when the
    command is not valid in the current state and is therefore ignored).
    """

    def __init__(self) -> None:
        self.state = DriveState.NOT_READY_TO_SWITCH_ON
        self._fault_reset_bit = False

    def power_up(self) -> tuple[int, ...]:
        """Transitions 0 and 1: self-test done, the drive waits in SWITCH ON DISABLED."""
        self.state = DriveState.SWITCH_ON_DISABLED
        self._fault_reset_bit = False
        return (0, 1)

    def on_controlword(self, controlword: int, quick_stop_option: int) -> tuple[int, ...]:
        """Apply a written controlword.

        Fault reset (transition 15) fires only on the rising edge of bit 7 in FAULT.
        Transition 16 (QUICK STOP ACTIVE -> OPERATION ENABLED) is allowed only for
        quick stop option codes 5-8 (0x605A), which hold the drive in QUICK STOP ACTIVE.
        """
        reset_bit = bool(controlword & FAULT_RESET_BIT)
        rising_edge = reset_bit and not self._fault_reset_bit
        self._fault_reset_bit = reset_bit
        if self.state is DriveState.FAULT:
            if rising_edge:
                self.state = DriveState.SWITCH_ON_DISABLED
                return (15,)
            return ()
        command = decode_command(controlword)
        if command is None or self.state is DriveState.FAULT_REACTION_ACTIVE:
            return ()
        if (self.state, command) == (DriveState.QUICK_STOP_ACTIVE, Command.ENABLE_OPERATION) \
                and quick_stop_option not in QUICK_STOP_HOLD_OPTIONS:
            return ()
        transitions, new_state = TRANSITIONS.get((self.state, command), ((), self.state))
        self.state = new_state
        return transitions

    def on_fault(self) -> tuple[int, ...]:
        """Transition 13: a fault was detected; the fault reaction starts."""
        if self.state in (DriveState.FAULT_REACTION_ACTIVE, DriveState.FAULT):
            return ()
        self.state = DriveState.FAULT_REACTION_ACTIVE
        return (13,)

    def on_fault_reaction_done(self) -> tuple[int, ...]:
        """Transition 14: the fault reaction is complete, the drive function is disabled."""
        if self.state is not DriveState.FAULT_REACTION_ACTIVE:
            return ()
        self.state = DriveState.FAULT
        return (14,)

    def on_quick_stop_done(self) -> tuple[int, ...]:
        """Transition 12 (automatic): the quick stop ramp ended with option codes 0-4."""
        if self.state is not DriveState.QUICK_STOP_ACTIVE:
            return ()
        self.state = DriveState.SWITCH_ON_DISABLED
        return (12,)
