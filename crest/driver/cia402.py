"""CiA 402 (IEC 61800-7-201) words: the state a statusword shows, the controlword commands, the modes.

Statusword 0x6041, bits 0-3, 5 and 6 show the state (x = don't care):

    state                    mask  value   bits 6 5 3 2 1 0
    not ready to switch on   0x4F  0x00         0 x 0 0 0 0
    switch on disabled       0x4F  0x40         1 x 0 0 0 0
    ready to switch on       0x6F  0x21         0 1 0 0 0 1
    switched on              0x6F  0x23         0 1 0 0 1 1
    operation enabled        0x6F  0x27         0 1 0 1 1 1
    quick stop active        0x6F  0x07         0 0 0 1 1 1
    fault reaction active    0x4F  0x0F         0 x 1 1 1 1
    fault                    0x4F  0x08         0 x 1 0 0 0

Other statusword bits: 10 target reached; 12 and 13 depend on the mode of operation
(profile position: set-point acknowledge, following error; cyclic synchronous position:
drive follows the command, following error; homing: homing attained, homing error).

Controlword 0x6040 commands, bits 7 and 3..0 (CiA 402 transition numbers in brackets):

    shutdown          0x06   SWITCH ON DISABLED / SWITCHED ON / OPERATION ENABLED -> READY TO SWITCH ON (2, 6, 8)
    switch on         0x07   READY TO SWITCH ON -> SWITCHED ON (3)
    enable operation  0x0F   SWITCHED ON -> OPERATION ENABLED (4)
    disable voltage   0x00   any powered state -> SWITCH ON DISABLED (7, 9, 10, 12)
    quick stop        0x02   OPERATION ENABLED -> QUICK STOP ACTIVE (11); READY/SWITCHED ON -> SWITCH ON DISABLED
    fault reset       0x80   rising edge of bit 7 only: FAULT -> SWITCH ON DISABLED (15)

Mode bits of the controlword: 4 new set-point (profile position) or homing start (homing),
5 change set immediately, 6 relative target, 8 halt.
"""

from __future__ import annotations

import enum


class Cia402State(enum.Enum):
    NOT_READY_TO_SWITCH_ON = "NOT READY TO SWITCH ON"
    SWITCH_ON_DISABLED = "SWITCH ON DISABLED"
    READY_TO_SWITCH_ON = "READY TO SWITCH ON"
    SWITCHED_ON = "SWITCHED ON"
    OPERATION_ENABLED = "OPERATION ENABLED"
    QUICK_STOP_ACTIVE = "QUICK STOP ACTIVE"
    FAULT_REACTION_ACTIVE = "FAULT REACTION ACTIVE"
    FAULT = "FAULT"

    def __str__(self) -> str:
        return self.value


_STATUSWORD_PATTERNS = (  # (mask, value, state), table in the module docstring
    (0x4F, 0x00, Cia402State.NOT_READY_TO_SWITCH_ON),
    (0x4F, 0x40, Cia402State.SWITCH_ON_DISABLED),
    (0x6F, 0x21, Cia402State.READY_TO_SWITCH_ON),
    (0x6F, 0x23, Cia402State.SWITCHED_ON),
    (0x6F, 0x27, Cia402State.OPERATION_ENABLED),
    (0x6F, 0x07, Cia402State.QUICK_STOP_ACTIVE),
    (0x4F, 0x0F, Cia402State.FAULT_REACTION_ACTIVE),
    (0x4F, 0x08, Cia402State.FAULT),
)

#: States in which the power stage may drive the motor.
ENERGISED_STATES = frozenset({Cia402State.OPERATION_ENABLED, Cia402State.QUICK_STOP_ACTIVE})


def state_from_statusword(statusword: int) -> Cia402State:
    """The state a statusword shows; ValueError for a pattern CiA 402 does not define."""
    for mask, value, state in _STATUSWORD_PATTERNS:
        if statusword & mask == value:
            return state
    raise ValueError(f"statusword 0x{statusword:04X} shows no CiA 402 state")


# Controlword commands (bits 7, 3..0).
SHUTDOWN = 0x0006
SWITCH_ON = 0x0007
ENABLE_OPERATION = 0x000F
DISABLE_VOLTAGE = 0x0000
QUICK_STOP = 0x0002
FAULT_RESET = 0x0080

# Controlword mode bits.
NEW_SET_POINT = 0x0010       # profile position: rising edge hands 0x607A over; homing: start
CHANGE_SET_IMMEDIATELY = 0x0020
HALT = 0x0100

# Statusword bits.
TARGET_REACHED = 0x0400
SET_POINT_ACKNOWLEDGE = 0x1000   # profile position
HOMING_ATTAINED = 0x1000         # homing
FOLLOWING_ERROR = 0x2000         # profile position, cyclic synchronous position
HOMING_ERROR = 0x2000            # homing


class OperationMode(enum.IntEnum):
    """Modes of operation 0x6060 (and display 0x6061) the driver uses."""

    PROFILE_POSITION = 1
    HOMING = 6
    CYCLIC_SYNC_POSITION = 8


#: Supported drive modes 0x6502: bit (mode - 1) is set for each supported mode.
REQUIRED_SUPPORTED_MODES = sum(1 << (mode - 1) for mode in OperationMode)


def command_toward_enabled(state: Cia402State, previous_controlword: int) -> int | None:
    """The controlword that takes a drive one transition closer to OPERATION ENABLED.

    FAULT is left by a fault reset, which acts only on a rising edge of bit 7, so the
    drive first gets 0x00 (bit 7 low) and then 0x80. SWITCH ON DISABLED -> shutdown (2),
    READY TO SWITCH ON -> switch on (3), SWITCHED ON -> enable operation (4); QUICK STOP
    ACTIVE is left through SWITCH ON DISABLED (disable voltage, 12). None: the drive is
    enabled already, or is busy (NOT READY TO SWITCH ON, FAULT REACTION ACTIVE) and must
    be waited for.
    """
    if state is Cia402State.FAULT:
        return FAULT_RESET if previous_controlword == DISABLE_VOLTAGE else DISABLE_VOLTAGE
    return {
        Cia402State.SWITCH_ON_DISABLED: SHUTDOWN,
        Cia402State.READY_TO_SWITCH_ON: SWITCH_ON,
        Cia402State.SWITCHED_ON: ENABLE_OPERATION,
        Cia402State.QUICK_STOP_ACTIVE: DISABLE_VOLTAGE,
    }.get(state)
