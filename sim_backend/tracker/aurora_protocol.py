"""The NDI Aurora serial protocol as the simulated tracker speaks it: command decoding and reply encoding.

Wire format (NDI Combined API, as implemented by the open-source ndicapi):

- A command is ``NAME:ARGS<CRC16>\\r`` or ``NAME ARGS\\r``. With a colon the four uppercase hex digits of
  the CRC-16 of ``NAME:ARGS`` follow the arguments; with a space there is no CRC.
- A reply is ``BODY<CRC16>\\r``: the body (``OKAY``, ``ERRORnn`` or command data), then the four
  uppercase hex digits of the CRC-16 of the body, then a carriage return.
- The CRC is NDI's CalcCRC16: polynomial x^16 + x^15 + x^2 + 1, bytes fed LSB first, initial value 0,
  no final XOR, which is the catalogued CRC-16/ARC (check value 0xBB3D). ``OKAY`` -> ``A896``.

Only the subset the crest tracker driver uses is modelled: INIT, COMM, PHSR, PINIT, PENA, TSTART, TSTOP and TX
with reply option 0001 (transforms and status).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from crccheck.crc import Crc16Arc

# Error codes the Aurora answers with (``ERRORnn``), ndicapi.h names in comments.
ERR_INVALID_COMMAND = 0x01  # NDI_INVALID
ERR_TOO_LONG = 0x02  # NDI_TOO_LONG
ERR_BAD_CRC = 0x04  # NDI_BAD_COMMAND_CRC
ERR_PARAMETERS = 0x07  # NDI_PARAMETERS: incorrect number of command parameters
ERR_INVALID_PORT = 0x08  # NDI_INVALID_PORT: invalid port handle
ERR_TRACKING_PRIORITY = 0x09  # NDI_INVALID_MODE: tracking priority must be S, D or B
ERR_BAD_MODE = 0x0C  # NDI_BAD_MODE: command invalid in the current mode
ERR_PORT_NOT_INIT = 0x0E  # NDI_PORT_NOT_INIT
ERR_NOT_INITIALIZED = 0x10  # NDI_INITIALIZATION: system not initialized
ERR_PARAMETER_RANGE = 0x23  # NDI_PARAMETER_RANGE: command parameter out of range

# Port status bits (PHSR uses the low 12 bits as 3 hex digits, TX all 32 bits as 8 hex digits).
PORT_OCCUPIED = 0x0001
PORT_INITIALIZED = 0x0010
PORT_ENABLED = 0x0020
PORT_OUT_OF_VOLUME = 0x0040

# COMM baud-rate codes (first argument character), from ndicapi's COMM helper.
COMM_BAUD_BPS = {"0": 9600, "1": 14400, "2": 19200, "3": 38400, "4": 57600, "5": 115200,
                 "6": 921600, "7": 1228739, "A": 230400}

MAX_COMMAND_BYTES = 1024
"""A command line longer than this (without its CR) is answered with ERROR02."""

_NAME = re.compile(r"[A-Z0-9]*")
_HEX4 = re.compile(r"[0-9A-Fa-f]{4}")


class CommandError(Exception):
    """A command the tracker rejects; ``code`` is the NDI error code sent back as ``ERRORnn``."""

    def __init__(self, code: int, why: str):
        super().__init__(f"ERROR{code:02X}: {why}")
        self.code = code


@dataclass(frozen=True)
class Command:
    """One decoded command: ``name`` (e.g. ``"PENA"``) and its argument text without the CRC."""

    name: str
    args: str


def crc16(data: bytes) -> int:
    """NDI CalcCRC16 of ``data`` (CRC-16/ARC, see the module docstring)."""
    return Crc16Arc.calc(data)


def decode_command(line: bytes) -> Command:
    """Decode one command line (without its terminating CR).

    The name is the leading run of ``A-Z0-9`` (ndicapi's rule). A colon after it means the last four
    characters are the CRC of everything before them; a space means no CRC; nothing means no arguments.
    Raises CommandError with ERROR01 (not ASCII / no name / unknown separator), ERROR02 (too long)
    or ERROR04 (missing or wrong CRC).
    """
    if len(line) > MAX_COMMAND_BYTES:
        raise CommandError(ERR_TOO_LONG, f"command of {len(line)} bytes exceeds {MAX_COMMAND_BYTES}")
    try:
        text = line.decode("ascii")
    except UnicodeDecodeError as exc:
        raise CommandError(ERR_INVALID_COMMAND, "command is not ASCII") from exc
    name = _NAME.match(text).group()
    rest = text[len(name):]
    if not name:
        raise CommandError(ERR_INVALID_COMMAND, f"no command name in {text!r}")
    if rest == "":
        return Command(name, "")
    if rest[0] == " ":
        return Command(name, rest[1:])
    if rest[0] != ":":
        raise CommandError(ERR_INVALID_COMMAND, f"command name {name!r} followed by {rest[0]!r}")
    crc_text = rest[-4:]
    if len(rest) < 5 or not _HEX4.fullmatch(crc_text):
        raise CommandError(ERR_BAD_CRC, f"{name}: command with ':' lacks its 4-digit CRC")
    if int(crc_text, 16) != crc16(line[:-4]):
        raise CommandError(ERR_BAD_CRC, f"{name}: CRC {crc_text} does not match {crc16(line[:-4]):04X}")
    return Command(name, rest[1:-4])


def encode_reply(body: str, *, corrupt_crc: bool = False) -> bytes:
    """Frame a reply body as ``BODY<CRC16 as 4 uppercase hex>\\r``.

    ``corrupt_crc`` inverts the CRC (fault injection): the framing stays valid, the check fails.
    """
    data = body.encode("ascii")
    crc = crc16(data) ^ (0xFFFF if corrupt_crc else 0)
    return data + f"{crc:04X}\r".encode("ascii")


def error_body(code: int) -> str:
    """The body of an error reply: ``ERROR`` and the code as two hex digits."""
    return f"ERROR{code:02X}"


def phsr_body(handles: list[tuple[int, int]]) -> str:
    """PHSR reply body: handle count (2 hex), then per handle its number (2 hex) and status (3 hex)."""
    return f"{len(handles):02X}" + "".join(f"{handle:02X}{status & 0xFFF:03X}" for handle, status in handles)


def _signed(value: float, scale: float, width: int) -> str:
    """Signed fixed point: sign then ``width - 1`` digits of ``round(value * scale)``."""
    count = round(value * scale)
    if abs(count) >= 10 ** (width - 1):
        raise ValueError(f"{value} does not fit {width} characters at scale {scale}")
    return f"{'-' if count < 0 else '+'}{abs(count):0{width - 1}d}"


def transform_text(q: tuple[float, float, float, float], position_mm: tuple[float, float, float],
                   rms_error_mm: float) -> str:
    """The 51-character TX transform: q0 qx qy qz as sign + 5 digits (4 implied decimals), x y z in mm as
    sign + 6 digits (2 implied decimals), RMS error as sign + 5 digits (4 implied decimals).

    Raises ValueError when a value does not fit its field (|x| >= 10000 mm, |q| >= 10).
    """
    return ("".join(_signed(v, 1e4, 6) for v in q) + "".join(_signed(v, 1e2, 7) for v in position_mm)
            + _signed(rms_error_mm, 1e4, 6))


def tx_record(handle: int, transform: str | None, port_status: int, frame: int) -> str:
    """One TX (option 0001) handle record, LF-terminated: handle (2 hex), the transform or ``MISSING``,
    port status (8 hex), frame number (8 hex)."""
    return f"{handle:02X}{transform or 'MISSING'}{port_status:08X}{frame & 0xFFFFFFFF:08X}\n"


def tx_body(records: list[str], system_status: int) -> str:
    """TX reply body: handle count (2 hex), the handle records, system status (4 hex)."""
    return f"{len(records):02X}" + "".join(records) + f"{system_status:04X}"
