"""Parsing NDI Aurora replies: framing, CRC, and the OKAY / ERROR / PHSR / TX bodies.

A reply is ``BODY<CRC16>\\r``: the body, four hex digits of its CRC-16, a carriage return. The CRC is NDI's
CalcCRC16 (polynomial x^16 + x^15 + x^2 + 1, LSB first, initial value 0, no final XOR), which is the
catalogued CRC-16/ARC; ``OKAY`` carries ``A896``. A body ``ERRORnn`` is the device refusing a command.

TX with reply option 0001 (the layout ndicapi's TX helper reads):

    nn                         handle count, 2 hex
    per handle, LF-terminated:
      hh                       port handle, 2 hex
      one of
        q0 qx qy qz            4 x 6 chars: sign + 5 digits, 4 implied decimals (unit quaternion)
        x y z                  3 x 7 chars: sign + 6 digits, 2 implied decimals, mm
        error                  6 chars: sign + 5 digits, 4 implied decimals, RMS mm
      or MISSING / DISABLED
      port status              8 hex
      frame number             8 hex
      (further data for other reply options, skipped up to the LF, as ndicapi does)
      or UNOCCUPIED            (nothing else in the record)
    ssss                       system status, 4 hex

Every parser here raises TrackerProtocolError (subclasses: TrackerCrcError for a CRC mismatch,
TrackerErrorReply for ``ERRORnn``) on any input it cannot read; nothing else escapes, and the work is
linear in the reply length.
"""

from __future__ import annotations

import enum
import re
from dataclasses import dataclass

from crccheck.crc import Crc16Arc

# Texts of the device error codes, from ndicapi's ndiErrorString.
ERROR_TEXTS = {
    0x01: "invalid command", 0x02: "command too long", 0x03: "command too short",
    0x04: "invalid CRC calculated for command", 0x05: "time-out on command execution",
    0x06: "unable to set up new communication parameters", 0x07: "incorrect number of command parameters",
    0x08: "invalid port handle selected", 0x09: "invalid tracking priority selected (must be S, D or B)",
    0x0A: "invalid LED selected", 0x0B: "invalid LED state selected", 0x0C: "command is invalid in the current mode",
    0x0D: "no tool assigned to the selected port handle", 0x0E: "selected port handle not initialized",
    0x0F: "selected port handle not enabled", 0x10: "system not initialized", 0x11: "unable to stop tracking",
    0x12: "unable to start tracking", 0x13: "unable to initialize Tool-in-Port",
    0x14: "invalid Position Sensor or Field Generator characterization parameters",
    0x15: "unable to initialize the Measurement System", 0x1A: "internal Measurement System error",
    0x23: "command parameter out of range", 0x29: "main processor firmware corrupt",
    0x2B: "requested handle has not been allocated", 0x2C: "requested handle has become unoccupied",
    0x2D: "all handles have been allocated",
}

_HEX = re.compile(rb"[0-9A-Fa-f]+")
_PRINTABLE = re.compile(rb"[ -~]*")
_TRANSFORM = re.compile(rb"([+-]\d{5}){4}([+-]\d{6}){3}[+-]\d{5}")


class TrackerProtocolError(ValueError):
    """A reply that cannot be read: broken framing, a CRC mismatch, wrong field widths or characters."""


class TrackerCrcError(TrackerProtocolError):
    """A well-framed reply whose CRC does not match its body (line noise or a faulty device)."""


class TrackerErrorReply(TrackerProtocolError):
    """The device answered ``ERRORnn``; ``code`` is nn."""

    def __init__(self, code: int, command: str):
        super().__init__(f"tracker refused {command}: ERROR{code:02X} "
                         f"({ERROR_TEXTS.get(code, 'unrecognized error code')})")
        self.code = code


class ToolState(str, enum.Enum):
    """What a TX record says about a handle."""

    VALID = "valid"
    MISSING = "missing"
    DISABLED = "disabled"
    UNOCCUPIED = "unoccupied"


@dataclass(frozen=True)
class PortHandle:
    """One PHSR entry: the handle and its 12-bit status (0x001 occupied, 0x010 initialized, 0x020 enabled)."""

    handle: int
    status: int


@dataclass(frozen=True)
class HandleRecord:
    """One handle of a TX reply. ``q`` (q0, qx, qy, qz), ``position_mm`` and ``rms_error_mm`` are set only
    when ``state`` is VALID; ``port_status`` and ``frame`` are 0 for an UNOCCUPIED handle."""

    handle: int
    state: ToolState
    port_status: int
    frame: int
    q: tuple[float, float, float, float] | None = None
    position_mm: tuple[float, float, float] | None = None
    rms_error_mm: float | None = None


@dataclass(frozen=True)
class TxReply:
    """A parsed TX reply: the handle records in reply order and the 16-bit system status."""

    handles: tuple[HandleRecord, ...]
    system_status: int

    def record(self, handle: int) -> HandleRecord:
        """The record of ``handle``; TrackerProtocolError when the reply has none."""
        for entry in self.handles:
            if entry.handle == handle:
                return entry
        listed = ", ".join(f"{entry.handle:02X}" for entry in self.handles) or "none"
        raise TrackerProtocolError(f"TX reply has no record for port handle {handle:02X} (handles: {listed})")


def crc16(data: bytes) -> int:
    """NDI CalcCRC16 of ``data`` (CRC-16/ARC)."""
    return Crc16Arc.calc(data)


def with_crc(command: str) -> bytes:
    """A command ready to send: ``NAME:ARGS`` + its CRC as 4 uppercase hex + CR (the colon form)."""
    data = command.encode("ascii")
    return data + f"{crc16(data):04X}\r".encode("ascii")


def reply_body(raw: bytes, command: str) -> bytes:
    """Check the framing and CRC of a raw reply and return its body.

    ``command`` names the command in error messages. Raises TrackerErrorReply for a well-formed
    ``ERRORnn`` reply and TrackerProtocolError for anything malformed.
    """
    if not raw.endswith(b"\r"):
        raise TrackerProtocolError(f"{command} reply {_show(raw)} is not terminated by CR (incomplete or timed out)")
    if len(raw) < 5:
        raise TrackerProtocolError(f"{command} reply {_show(raw)} is shorter than its 4-digit CRC")
    body, crc_text = raw[:-5], raw[-5:-1]
    if not _HEX.fullmatch(crc_text):
        raise TrackerProtocolError(f"{command} reply {_show(raw)}: CRC field {_show(crc_text)} is not 4 hex digits")
    if b"\r" in body or not _PRINTABLE.fullmatch(body.replace(b"\n", b"")):
        raise TrackerProtocolError(f"{command} reply {_show(raw)} contains bytes outside printable ASCII")
    if int(crc_text, 16) != crc16(body):
        raise TrackerCrcError(f"{command} reply {_show(raw)}: CRC {crc_text.decode()} "
                                   f"does not match the body's {crc16(body):04X}")
    if body.startswith(b"ERROR"):
        code = body[5:]
        if len(code) != 2 or not _HEX.fullmatch(code):
            raise TrackerProtocolError(f"{command} reply {_show(raw)}: error code is not 2 hex digits")
        raise TrackerErrorReply(int(code, 16), command)
    return body


def parse_okay(raw: bytes, command: str) -> None:
    """Accept an ``OKAY`` reply to ``command``; raise for anything else."""
    body = reply_body(raw, command)
    if body != b"OKAY":
        raise TrackerProtocolError(f"{command} reply {_show(raw)}: expected OKAY")


def parse_phsr(raw: bytes) -> tuple[PortHandle, ...]:
    """PHSR reply: handle count (2 hex), then per handle the handle (2 hex) and its status (3 hex)."""
    body = reply_body(raw, "PHSR")
    count = _hex_field(body, 0, 2, "PHSR handle count")
    if len(body) != 2 + 5 * count:
        raise TrackerProtocolError(f"PHSR reply {_show(raw)}: {count} handles need {2 + 5 * count} characters, "
                                   f"got {len(body)}")
    return tuple(PortHandle(_hex_field(body, 2 + 5 * i, 2, "PHSR handle"),
                            _hex_field(body, 4 + 5 * i, 3, "PHSR handle status")) for i in range(count))


def parse_tx(raw: bytes) -> TxReply:
    """TX reply with reply option 0001, laid out as in the module docstring."""
    body = reply_body(raw, "TX")
    if len(body) < 6:
        raise TrackerProtocolError(f"TX reply {_show(raw)}: needs at least a handle count and a system status")
    count = _hex_field(body, 0, 2, "TX handle count")
    system_status = _hex_field(body, len(body) - 4, 4, "TX system status")
    section = body[2:-4]
    if count == 0:
        if section:
            raise TrackerProtocolError(f"TX reply {_show(raw)}: data after a handle count of 0")
        return TxReply((), system_status)
    if not section.endswith(b"\n"):
        raise TrackerProtocolError(f"TX reply {_show(raw)}: the last handle record is not LF-terminated")
    records = section[:-1].split(b"\n")
    if len(records) != count:
        raise TrackerProtocolError(f"TX reply {_show(raw)}: handle count {count} but {len(records)} records")
    return TxReply(tuple(_handle_record(record) for record in records), system_status)


def _handle_record(record: bytes) -> HandleRecord:
    handle = _hex_field(record, 0, 2, "TX port handle")
    rest = record[2:]
    if rest == b"UNOCCUPIED":
        return HandleRecord(handle, ToolState.UNOCCUPIED, 0, 0)
    q = position_mm = rms_error_mm = None
    if rest.startswith(b"MISSING"):
        state, width = ToolState.MISSING, 7
    elif rest.startswith(b"DISABLED"):
        state, width = ToolState.DISABLED, 8
    elif _TRANSFORM.match(rest):
        state, width = ToolState.VALID, 51
        q = tuple(int(rest[i:i + 6]) * 1e-4 for i in range(0, 24, 6))
        position_mm = tuple(int(rest[i:i + 7]) * 1e-2 for i in range(24, 45, 7))
        rms_error_mm = int(rest[45:51]) * 1e-4
    else:
        raise TrackerProtocolError(f"TX record for handle {handle:02X}: {_show(rest[:51])} is neither a "
                                   "51-character transform nor MISSING / DISABLED / UNOCCUPIED")
    port_status = _hex_field(rest, width, 8, f"TX port status of handle {handle:02X}")
    frame = _hex_field(rest, width + 8, 8, f"TX frame number of handle {handle:02X}")
    return HandleRecord(handle, state, port_status, frame, q, position_mm, rms_error_mm)


def _hex_field(text: bytes, start: int, width: int, what: str) -> int:
    field = text[start:start + width]
    if len(field) != width or not _HEX.fullmatch(field):
        raise TrackerProtocolError(f"{what}: expected {width} hex digits at offset {start}, got {_show(field)}")
    return int(field, 16)


def _show(data: bytes) -> str:
    """A reply excerpt for an error message, at most 80 bytes."""
    return repr(data[:80]) + ("..." if len(data) > 80 else "")
