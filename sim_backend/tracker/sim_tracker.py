"""A simulated NDI Aurora tip tracker on a pseudo-terminal.

The tracker owns the master side of ``os.openpty()``; a client opens ``port_name`` (the slave device) with
pyserial exactly as it would open the Aurora's USB serial port. A reader thread decodes each CR-terminated
command and writes the byte-exact reply (see ``aurora_protocol``). The tool's position is the tip the
injected ``tip_source`` returns, in the testbed base frame (identity registration, identity orientation),
plus Gaussian noise; a seeded fraction of frames is reported ``MISSING``.

Device model: one sensor on port handle ``tool_handle``. After INIT its handle is occupied; PINIT initializes
it, PENA enables it, TSTART enters tracking mode, TSTOP leaves it. INIT is accepted in any mode and starts
over. The tracker measures on demand: each TX reply is a new frame, so the frame number counts TX replies
(TSTART:80 resets it). COMM is acknowledged; a pseudo-terminal has no baud rate, so nothing else changes.
"""

from __future__ import annotations

import enum
import logging
import os
import select
import string
import threading
import tty
from collections import deque
from collections.abc import Callable

import numpy as np

from sim_backend.tracker import aurora_protocol as proto

_log = logging.getLogger(__name__)

_POLL_S = 0.05
"""How often the reader thread checks for stop while the line is idle."""

_WRITE_TIMEOUT_S = 0.5
"""A reply the client does not read within this time is dropped, like a UART overrun."""

_IDENTITY_Q = (1.0, 0.0, 0.0, 0.0)


class TrackerFault(str, enum.Enum):
    """Faults the simulated tracker can be given (``--fault tracker:KIND@SECONDS``)."""

    DISCONNECT = "disconnect"  # the line goes silent: commands are swallowed, nothing is answered
    CRC = "crc"  # every reply carries a wrong CRC
    MISSING_TOOL = "missing_tool"  # the sensor is reported MISSING in every frame


class SimTracker:
    """Simulated Aurora on a pseudo-terminal.

    Args:
        tip_source: called from the reader thread for every TX; returns the tip position in mm, shape (3,),
            in the base frame, or None when there is no tip to report. Must be thread-safe.
        noise_mm: standard deviation of the Gaussian noise added to each coordinate, mm.
        dropout: probability in [0, 1] that a frame reports the tool MISSING.
        seed: seed of the numpy Generator that draws noise and dropout.
        tool_handle: the port handle the sensor sits on (the testbed's ``[tracker].tool_port``).
        draw_key: None, each frame draws its noise and dropout after the previous frame's; or
            called (after tip_source) for the instant the frame describes, and the frame's draws come
            from the Generator of (seed, that key). Simulated time keys them on the plant's step:
            a frame asked for again at the same instant (the driver's retry after a reply it
            thought lost, on a loaded machine) repeats it instead of shifting every later frame's
            noise, so a recording in simulated time does not depend on how busy the machine was.
    """

    def __init__(self, tip_source: Callable[[], np.ndarray | None], *, noise_mm: float = 0.0,
                 dropout: float = 0.0, seed: int = 0, tool_handle: int = 0x0A,
                 draw_key: Callable[[], int] | None = None):
        if noise_mm < 0.0:
            raise ValueError(f"tracker noise_mm must be >= 0, got {noise_mm}")
        if not 0.0 <= dropout <= 1.0:
            raise ValueError(f"tracker dropout must be in [0, 1], got {dropout}")
        if not 0x01 <= tool_handle <= 0xFF:
            raise ValueError(f"tracker tool_handle must be a port handle 0x01..0xFF, got {tool_handle:#x}")
        self.tip_source = tip_source
        self.noise_mm = noise_mm
        self.dropout = dropout
        self.tool_handle = tool_handle
        self._seed = seed
        self._rng = np.random.default_rng(seed)
        self.draw_key = draw_key
        self._faults: set[TrackerFault] = set()
        self._faults_lock = threading.Lock()
        self._initialized = False
        self._tracking = False
        self._port_status = 0
        self._frame = 0
        self.command_log: deque[proto.Command] = deque(maxlen=256)
        """The most recent commands the tracker accepted for decoding (name and arguments)."""
        self._master_fd, self._slave_fd = os.openpty()
        tty.setraw(self._slave_fd)  # no echo, no CR/LF translation before a client configures the line
        os.set_blocking(self._master_fd, False)
        self.port_name: str = os.ttyname(self._slave_fd)
        """The serial device a client opens, e.g. ``/dev/pts/3``."""
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, name=f"sim-aurora {self.port_name}", daemon=True)

    # -- lifecycle ------------------------------------------------------------------------------------------

    def start(self) -> SimTracker:
        """Start answering on ``port_name``."""
        self._thread.start()
        return self

    def stop(self) -> None:
        """Stop the reader thread and close both ends of the pseudo-terminal."""
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join()
        for fd in (self._master_fd, self._slave_fd):
            try:
                os.close(fd)
            except OSError:
                pass  # already closed
        self._master_fd = self._slave_fd = -1

    def __enter__(self) -> SimTracker:
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()

    # -- fault injection ------------------------------------------------------------------------------------

    def inject(self, fault: TrackerFault | str) -> None:
        """Switch a fault on; it lasts until ``clear``."""
        with self._faults_lock:
            self._faults.add(TrackerFault(fault))

    def clear(self, fault: TrackerFault | str) -> None:
        """Switch a fault off; after DISCONNECT the tracker answers again, in the state it had."""
        with self._faults_lock:
            self._faults.discard(TrackerFault(fault))

    @property
    def faults(self) -> frozenset[TrackerFault]:
        """The faults currently active."""
        with self._faults_lock:
            return frozenset(self._faults)

    @property
    def tracking(self) -> bool:
        """True between TSTART and TSTOP (or INIT)."""
        return self._tracking

    # -- the line -------------------------------------------------------------------------------------------

    def _serve(self) -> None:
        pending = bytearray()
        while not self._stop.is_set():
            readable, _, _ = select.select([self._master_fd], [], [], _POLL_S)
            if not readable:
                continue
            try:
                chunk = os.read(self._master_fd, 4096)
            except BlockingIOError:
                continue
            except OSError:  # EIO: no slave side open; wait for a client
                self._stop.wait(_POLL_S)
                continue
            if TrackerFault.DISCONNECT in self.faults:
                pending.clear()
                continue
            pending += chunk
            while (end := pending.find(b"\r")) >= 0:
                line = bytes(pending[:end])
                del pending[:end + 1]
                self._write(self.answer(line))
            if len(pending) > proto.MAX_COMMAND_BYTES:
                pending.clear()
                self._write(self._frame_reply(proto.error_body(proto.ERR_TOO_LONG)))

    def _write(self, reply: bytes) -> None:
        view = memoryview(reply)
        while view:
            _, writable, _ = select.select([], [self._master_fd], [], _WRITE_TIMEOUT_S)
            if not writable:
                _log.warning("simulated tracker: client on %s is not reading; reply dropped", self.port_name)
                return
            try:
                view = view[os.write(self._master_fd, view):]
            except BlockingIOError:
                continue

    def _frame_reply(self, body: str) -> bytes:
        return proto.encode_reply(body, corrupt_crc=TrackerFault.CRC in self.faults)

    # -- commands -------------------------------------------------------------------------------------------

    def answer(self, line: bytes) -> bytes:
        """The reply bytes to one command line (without its CR), exactly as the reader thread sends them.

        Advances the tracker's state; call it directly only on a tracker that is not started.
        """
        try:
            command = proto.decode_command(line)
            self.command_log.append(command)
            handler = self._handlers.get(command.name)
            if handler is None:
                raise proto.CommandError(proto.ERR_INVALID_COMMAND, f"unknown command {command.name}")
            if command.name not in ("INIT", "COMM") and not self._initialized:
                raise proto.CommandError(proto.ERR_NOT_INITIALIZED, f"{command.name} before INIT")
            body = handler(self, command.args)
        except proto.CommandError as exc:
            body = proto.error_body(exc.code)
        return self._frame_reply(body)

    def _init(self, args: str) -> str:
        _expect_length(args, 0, "INIT")
        self._initialized = True
        self._tracking = False
        self._port_status = proto.PORT_OCCUPIED
        return "OKAY"

    def _comm(self, args: str) -> str:
        """COMM:BDPSH: baud code, data bits (0=8, 1=7), parity (0 none, 1 odd, 2 even), stop bits, handshake."""
        _expect_length(args, 5, "COMM")
        if args[0] not in proto.COMM_BAUD_BPS or args[1] not in "01" or args[2] not in "012" \
                or args[3] not in "01" or args[4] not in "01":
            raise proto.CommandError(proto.ERR_PARAMETER_RANGE, f"COMM parameters {args!r}")
        return "OKAY"

    def _phsr(self, args: str) -> str:
        """PHSR:nn lists handles: 00 all, 01 to be freed, 02 not initialized, 03 not enabled, 04 enabled."""
        mode = _hex_args(args or "00", 2, "PHSR")
        if self._tracking:
            raise proto.CommandError(proto.ERR_BAD_MODE, "PHSR in tracking mode")
        status = self._port_status
        listed = {
            0x00: True,
            0x01: False,
            0x02: not status & proto.PORT_INITIALIZED,
            0x03: bool(status & proto.PORT_INITIALIZED) and not status & proto.PORT_ENABLED,
            0x04: bool(status & proto.PORT_ENABLED),
        }
        if mode not in listed:
            raise proto.CommandError(proto.ERR_PARAMETER_RANGE, f"PHSR reply option {mode:02X}")
        return proto.phsr_body([(self.tool_handle, status)] if listed[mode] else [])

    def _pinit(self, args: str) -> str:
        self._check_handle(_hex_args(args, 2, "PINIT"), "PINIT")
        self._port_status |= proto.PORT_INITIALIZED
        return "OKAY"

    def _pena(self, args: str) -> str:
        """PENA:hhP enables handle hh with tracking priority P: S static, D dynamic, B button box."""
        _expect_length(args, 3, "PENA")
        self._check_handle(_hex_args(args[:2], 2, "PENA"), "PENA")
        if args[2] not in "SDB":
            raise proto.CommandError(proto.ERR_TRACKING_PRIORITY, f"PENA priority {args[2]!r}")
        if not self._port_status & proto.PORT_INITIALIZED:
            raise proto.CommandError(proto.ERR_PORT_NOT_INIT, "PENA before PINIT")
        self._port_status |= proto.PORT_ENABLED
        return "OKAY"

    def _tstart(self, args: str) -> str:
        """TSTART: enters tracking; TSTART:80 also resets the frame counter."""
        if args not in ("", "80"):
            raise proto.CommandError(proto.ERR_PARAMETER_RANGE, f"TSTART reply option {args!r}")
        if self._tracking:
            raise proto.CommandError(proto.ERR_BAD_MODE, "TSTART while tracking")
        if args == "80":
            self._frame = 0
        self._tracking = True
        return "OKAY"

    def _tstop(self, args: str) -> str:
        _expect_length(args, 0, "TSTOP")
        self._tracking = False
        return "OKAY"

    def _tx(self, args: str) -> str:
        """TX:0001 reports each enabled handle's transform, port status and frame, then system status 0000."""
        if _hex_args(args or "0001", 4, "TX") != 0x0001:
            raise proto.CommandError(proto.ERR_PARAMETER_RANGE, f"TX reply option {args} (the simulator has 0001)")
        if not self._tracking:
            raise proto.CommandError(proto.ERR_BAD_MODE, "TX outside tracking mode")
        self._frame += 1
        records = []
        if self._port_status & proto.PORT_ENABLED:
            transform, status = self._measure()
            records.append(proto.tx_record(self.tool_handle, transform, status, self._frame))
        return proto.tx_body(records, 0x0000)

    def _measure(self) -> tuple[str | None, int]:
        """This frame's transform text (None = MISSING) and port status."""
        status = self._port_status
        tip_mm = self.tip_source()
        rng = self._rng if self.draw_key is None else np.random.default_rng((self._seed, self.draw_key()))
        dropped = rng.random() < self.dropout
        noise_mm = rng.normal(0.0, self.noise_mm, 3)
        if dropped or tip_mm is None or TrackerFault.MISSING_TOOL in self.faults:
            return None, status
        position_mm = np.asarray(tip_mm, dtype=float).reshape(3) + noise_mm
        try:
            return proto.transform_text(_IDENTITY_Q, tuple(position_mm), min(self.noise_mm, 9.9999)), status
        except ValueError:  # beyond the +-9999.99 mm the reply can carry: outside the field
            return None, status | proto.PORT_OUT_OF_VOLUME

    def _check_handle(self, handle: int, name: str) -> None:
        if handle != self.tool_handle:
            raise proto.CommandError(proto.ERR_INVALID_PORT, f"{name}: no port handle {handle:02X}")
        if self._tracking:
            raise proto.CommandError(proto.ERR_BAD_MODE, f"{name} in tracking mode")

    _handlers: dict[str, Callable[[SimTracker, str], str]] = {
        "INIT": _init, "COMM": _comm, "PHSR": _phsr, "PINIT": _pinit, "PENA": _pena,
        "TSTART": _tstart, "TSTOP": _tstop, "TX": _tx,
    }


def _expect_length(args: str, length: int, name: str) -> None:
    if len(args) != length:
        raise proto.CommandError(proto.ERR_PARAMETERS, f"{name} takes {length} argument characters, got {args!r}")


def _hex_args(args: str, digits: int, name: str) -> int:
    _expect_length(args, digits, name)
    if not all(c in string.hexdigits for c in args):
        raise proto.CommandError(proto.ERR_PARAMETERS, f"{name} argument {args!r} is not hex")
    return int(args, 16)
