"""Which exit code and which words each kind of safety-stop cause gets.

EMCY (CiA 301 7.2.7): COB-ID 0x80 + node id, error code (UNSIGNED16) and error register.
The error code decides the exit code: 0x8611 following error (CiA 402) -> FOLLOWING_ERROR;
0x8130 heartbeat / life guard error (the drive lost the host) -> HEARTBEAT_LOST; 0x81xx other
CAN communication errors (error passive, bus-off recovery, overrun) -> BUS_ERROR; any other
code -> EMCY. 0x0000 (error reset) is not a fault.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import can
from canopen.emcy import EmcyError

from crest.driver.errors import DriveError, StopCause, Terminated
from crest.exit_codes import ExitCode

FOLLOWING_ERROR_CODE = 0x8611
HEARTBEAT_ERROR_CODE = 0x8130
CAN_COMMUNICATION_GROUP = 0x8100

_EMCY_TEXT = {
    0x2310: "continuous over current",
    0x3210: "DC link over-voltage",
    0x3220: "DC link under-voltage",
    0x4310: "drive over-temperature",
    0x7121: "motor blocked",
    0x8110: "CAN overrun",
    0x8120: "CAN error passive",
    0x8130: "heartbeat lost: the drive stopped hearing the host",
    0x8140: "recovered from CAN bus-off",
    0x8210: "PDO not processed: length error",
    0x8611: "following error",
}

# SocketCAN error class bits in the error frame's arbitration id (linux/can/error.h).
_ERROR_CLASSES = ((0x001, "TX timeout"), (0x002, "lost arbitration"), (0x004, "controller problem"),
                  (0x008, "protocol violation"), (0x010, "transceiver problem"), (0x020, "no ACK"),
                  (0x040, "bus-off"), (0x080, "bus error"), (0x100, "controller restarted"))


def emcy_text(code: int) -> str:
    """'0x2310 (continuous over current)' for an EMCY error code."""
    text = _EMCY_TEXT.get(code) or EmcyError(code, 0, b"", 0.0).get_desc().lower() or "vendor specific"
    return f"0x{code:04X} ({text})"


def emcy_cause(axis: str, code: int) -> StopCause:
    if code == FOLLOWING_ERROR_CODE:
        exit_code = ExitCode.FOLLOWING_ERROR
    elif code == HEARTBEAT_ERROR_CODE:
        exit_code = ExitCode.HEARTBEAT_LOST
    elif code & 0xFF00 == CAN_COMMUNICATION_GROUP:
        exit_code = ExitCode.BUS_ERROR
    else:
        exit_code = ExitCode.EMCY
    return StopCause(exit_code, axis, f"EMCY {emcy_text(code)}")


def error_frame_cause(message: can.Message) -> StopCause:
    classes = [name for bit, name in _ERROR_CLASSES if message.arbitration_id & bit]
    detail = ", ".join(classes) if classes else "error frame"
    return StopCause(ExitCode.BUS_ERROR, "bus", f"CAN error frame received ({detail}); check cabling, "
                                                "termination and that every node uses the same bitrate")


def heartbeat_cause(silences: Sequence[tuple[str, float]], timeout_s: float) -> StopCause:
    """The drives that went silent together, as (axis, seconds since its last heartbeat), the
    longest silence first: one drive is one lost drive; several at once (a bus or a power supply
    gone) are named together."""
    if len(silences) == 1:
        axis, silent_s = silences[0]
        return StopCause(ExitCode.HEARTBEAT_LOST, axis, f"no heartbeat for {silent_s:.3f} s (limit {timeout_s:g} s); "
                                                        "check the drive's power and CAN connection")
    seconds = [silent_s for _, silent_s in silences]
    return StopCause(ExitCode.HEARTBEAT_LOST, ", ".join(axis for axis, _ in silences),
                     f"no heartbeat from {len(silences)} drives at once for {min(seconds):.3f}-{max(seconds):.3f} s "
                     f"(limit {timeout_s:g} s); check the drives' power and the CAN connection")


def tension_cause(axis: str, tension_n: float, limit_n: float) -> StopCause:
    return StopCause(ExitCode.TENSION_LIMIT, axis, f"tension {tension_n:.1f} N exceeds max_tension_n {limit_n:g} N")


def following_error_cause(axis: str, detail: str) -> StopCause:
    return StopCause(ExitCode.FOLLOWING_ERROR, axis, f"following error: {detail}")


def tracker_cause(age_s: float, limit_s: float) -> StopCause:
    """``age_s`` is inf when no valid tip sample has arrived at all."""
    since = "yet" if math.isinf(age_s) else f"for {age_s:.3f} s"
    return StopCause(ExitCode.TRACKER_LOST, "tracker", f"no valid tip sample {since} (loss_timeout_s {limit_s:g} s) "
                                                       "during a closed-loop run; check the sensor and its cable")


def operator_cause(reason: str) -> StopCause:
    """An operator's stop that is not Ctrl-C (e.g. the live view's E-STOP button); same exit code."""
    return StopCause(ExitCode.INTERRUPTED, None, reason)


def exception_cause(error: BaseException) -> StopCause:
    """The cause for an exception that ends a driver call or a ``with Testbed`` block."""
    if isinstance(error, Terminated):
        return StopCause(ExitCode.TERMINATED, None, "terminated (SIGTERM)")
    if isinstance(error, KeyboardInterrupt):
        return StopCause(ExitCode.INTERRUPTED, None, "interrupted (Ctrl-C)")
    if isinstance(error, DriveError):
        return StopCause(error.exit_code, error.axis, str(error).removeprefix(f"{error.axis}: "))
    if isinstance(error, can.CanError):
        return StopCause(ExitCode.BUS_ERROR, "bus", f"CAN transmission failed ({error}); check the adapter and "
                                                    "that the bus is not off")
    return StopCause(ExitCode.EXCEPTION, None, f"unexpected {type(error).__name__}: {error}")
