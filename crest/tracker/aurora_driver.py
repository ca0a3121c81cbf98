"""The NDI Aurora tip-tracker driver: set-up, a polling thread, and reconnection.

Set-up (NDI Combined API, the order ndicapi-based tools use):
    INIT            at 9600 baud, the Aurora's rate after power-up; if that gets no valid reply the device may
                    still be at the rate an earlier session set, so INIT is retried at the configured rate
    COMM:B0000      B = baud code of the configured rate (8N1, no handshake); the host follows after OKAY
    PHSR:02 ->      PINIT:hh for every handle waiting for initialization
    PHSR:03 ->      PENA:hhD for every handle waiting to be enabled (dynamic tracking priority)
    PHSR:04         the configured tool handle must now be enabled
    TSTART
Then a thread sends ``TX:0001`` at ``rate_hz`` (or, with ``rate_hz=None``, once per ``fresh_sample`` call: on
demand, for a loop in simulated time that needs a frame per tracker period of its own clock and no others),
stamps each reply with time.monotonic() on arrival, checks its CRC and publishes a TipSample. A reply
timeout, a serial error, an ERROR reply or ``max_bad_replies`` consecutive unreadable replies (bad CRC,
bad widths) count as link loss: the port is closed and set-up is retried with exponential backoff
until it succeeds or ``stop()`` is called, or until ``port_alive`` says the port is gone for good.
"""

from __future__ import annotations

import enum
import logging
import string
import termios
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import serial

from crest.tracker import aurora_reply as reply
from crest.tracker.aurora_reply import ToolState, TrackerProtocolError

_log = logging.getLogger(__name__)

POWER_UP_BAUDRATE = 9600
"""The Aurora's rate after power-up or reset."""

COMM_BAUD_CODES = {9600: "0", 14400: "1", 19200: "2", 38400: "3", 57600: "4", 115200: "5", 230400: "A",
                   921600: "6", 1228739: "7"}
"""COMM's first argument character for each supported rate (ndicapi's COMM helper)."""

COMM_SETTLE_S = 0.1
"""Pause after COMM's OKAY before the host changes its rate, so the device has switched (as ndicapi does)."""

_MAX_REPLY_BYTES = 4096

_LINK_ERRORS = (serial.SerialException, OSError, TrackerProtocolError)
"""What a failed exchange raises: serial and OS errors (TrackerLinkError among them) and unreadable replies."""


class TrackerLinkError(ConnectionError):
    """The tracker could not be set up or stopped answering; the message says which step and why."""


class TrackerState(str, enum.Enum):
    """The driver's link state, as reported by ``state`` and the ``on_state`` callback."""

    CONNECTING = "connecting"  # first set-up in progress
    TRACKING = "tracking"  # TX polling, samples arriving
    RECONNECTING = "reconnecting"  # link lost; set-up is retried with backoff
    STOPPED = "stopped"


@dataclass(frozen=True)
class TipSample:
    """One tracker reading.

    t_s: time.monotonic() when the reply arrived, s.
    tip_mm: sensor position in the tracker frame, mm, shape (3,); None when the tool is MISSING or DISABLED.
    frame: the tracker's frame number.
    status: the handle's 32-bit port status (0x01 occupied, 0x10 initialized, 0x20 enabled, 0x40 out of volume).
    """

    t_s: float
    tip_mm: np.ndarray | None
    frame: int
    status: int


@dataclass(frozen=True)
class TrackerStats:
    """Counters since ``start()``: published samples, of which without a tip, rejected replies by cause,
    and completed reconnections."""

    samples: int = 0
    missing: int = 0
    crc_errors: int = 0
    bad_replies: int = 0
    timeouts: int = 0
    reconnects: int = 0


class AuroraDriver:
    """NDI Aurora driver over pyserial.

    Args:
        port: serial device, e.g. ``/dev/ttyUSB0`` or a simulator's pseudo-terminal.
        baudrate: the rate to run at after set-up (``[tracker].baudrate``); one of COMM_BAUD_CODES.
        tool_port: the sensor's port handle as two hex digits (``[tracker].tool_port``), e.g. ``"0A"``.
        rate_hz: TX polling rate; None: no polling, one TX per ``fresh_sample`` call (on demand).
        reply_timeout_s: longest wait for a TX reply before the link counts as lost.
        setup_timeout_s: longest wait for a reply to a set-up command (PINIT can take a second on hardware).
        max_bad_replies: consecutive unreadable replies (bad CRC or format) that count as link loss.
        backoff_s: first wait before a reconnection attempt; doubles per failure up to ``max_backoff_s``.
        on_state: called from the driver thread with (state, reason) on every state change.
        port_alive: asked before each reconnection attempt; False means the device behind ``port`` is
            gone for good, and the driver stops (state STOPPED) instead of opening ``port`` again. A
            virtual testbed's pseudo-terminal ends with its process, and the kernel may give its number
            to the next testbed that starts: opened again, it would reach that testbed's tracker, which
            would then answer two clients on one line. None: always try (a hardware port comes back
            under its name when its adapter is plugged in again).
    """

    def __init__(self, port: str, *, baudrate: int = 115200, tool_port: str = "0A", rate_hz: float | None = 40.0,
                 reply_timeout_s: float = 0.2, setup_timeout_s: float = 3.0, max_bad_replies: int = 3,
                 backoff_s: float = 0.1, max_backoff_s: float = 2.0,
                 on_state: Callable[[TrackerState, str], None] | None = None,
                 port_alive: Callable[[], bool] | None = None):
        if baudrate not in COMM_BAUD_CODES:
            raise ValueError(f"[tracker].baudrate {baudrate} is not an Aurora rate; use one of "
                             f"{sorted(COMM_BAUD_CODES)}")
        if not (isinstance(tool_port, str) and len(tool_port) == 2
                and all(c in string.hexdigits for c in tool_port) and tool_port != "00"):
            raise ValueError(f"[tracker].tool_port {tool_port!r} is not a port handle: use two hex digits, e.g. \"0A\"")
        self.tool_handle = int(tool_port, 16)
        if rate_hz is not None and not rate_hz > 0.0:
            raise ValueError(f"tracker rate_hz must be > 0 (or None: on demand), got {rate_hz}")
        if max_bad_replies < 1:
            raise ValueError(f"tracker max_bad_replies must be >= 1, got {max_bad_replies}")
        self.port = port
        self.baudrate = baudrate
        self.period_s = None if rate_hz is None else 1.0 / rate_hz
        self.reply_timeout_s = reply_timeout_s
        self.setup_timeout_s = setup_timeout_s
        self.max_bad_replies = max_bad_replies
        self.backoff_s = backoff_s
        self.max_backoff_s = max_backoff_s
        self.on_state = on_state
        self._port_alive = port_alive or (lambda: True)
        self._serial: serial.Serial | None = None
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._changed = threading.Condition()
        self._latest: TipSample | None = None
        self._latest_sent_s = -float("inf")     # when the TX of the latest sample was sent (monotonic)
        self._wanted = threading.Event()        # on demand: a fresh_sample call waits for a TX
        self._last_valid_t_s: float | None = None
        self._stats = TrackerStats()
        self._state = TrackerState.STOPPED
        self.last_error = ""
        """Why the link was last lost or why the last set-up failed ("" if never)."""

    # -- public ---------------------------------------------------------------------------------------------

    def start(self) -> AuroraDriver:
        """Set the tracker up and start polling. Raises TrackerLinkError if the first set-up fails."""
        if self._thread is not None:
            raise RuntimeError("AuroraDriver.start() called twice; create a new driver to restart")
        self._set_state(TrackerState.CONNECTING, f"opening {self.port}")
        try:
            self._connect()
        except _LINK_ERRORS as exc:
            self._close()
            self.last_error = str(exc)
            self._set_state(TrackerState.STOPPED, str(exc))
            raise TrackerLinkError(f"tracker on {self.port}: {exc}. Check the cable, the power and "
                                   "[tracker].port / baudrate / tool_port in the testbed config") from exc
        self._set_state(TrackerState.TRACKING, "set-up complete")
        self._thread = threading.Thread(target=self._run, name=f"aurora {self.port}", daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        """Stop polling, send TSTOP (best effort: the link may be down) and close the port.

        Returns once the exchange in progress has ended: within one reply or set-up timeout.
        """
        self._stop.set()
        self._wanted.set()          # an on-demand thread waiting for a request wakes and sees the stop
        if self._thread is not None:
            self._thread.join()
        if self._serial is not None:
            try:
                self._command("TSTOP:", self.reply_timeout_s)
            except _LINK_ERRORS as exc:
                _log.warning("tracker on %s: TSTOP failed while stopping: %s", self.port, exc)
        self._close()
        self._set_state(TrackerState.STOPPED, "stopped")

    def __enter__(self) -> AuroraDriver:
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()

    def latest(self) -> TipSample | None:
        """The most recent sample (its tip may be None), or None before the first one."""
        with self._changed:
            return self._latest

    def age_s(self) -> float:
        """Seconds since the last sample with a tip (inf if there was none): the tracker-loss measure."""
        with self._changed:
            last = self._last_valid_t_s
        return float("inf") if last is None else time.monotonic() - last

    def wait_next(self, timeout_s: float) -> TipSample:
        """Block until a sample newer than the current one is published; TimeoutError after ``timeout_s``."""
        with self._changed:
            before = self._latest
            if not self._changed.wait_for(lambda: self._latest is not before, timeout_s):
                raise TimeoutError(f"tracker on {self.port}: no new sample within {timeout_s} s "
                                   f"(state {self._state.value}, last error: {self.last_error or 'none'})")
            return self._latest

    def fresh_sample(self, timeout_s: float) -> TipSample:
        """Block until a sample whose TX was sent after this call is published (on demand: ask for it);
        TimeoutError after ``timeout_s``. Its tip describes the tracked tool at or after the call."""
        called_s = time.monotonic()
        with self._changed:
            self._wanted.set()
            if not self._changed.wait_for(lambda: self._latest_sent_s >= called_s, timeout_s):
                raise TimeoutError(f"tracker on {self.port}: no sample requested after the call within {timeout_s} s "
                                   f"(state {self._state.value}, last error: {self.last_error or 'none'})")
            return self._latest

    def wait_state(self, state: TrackerState, timeout_s: float) -> bool:
        """Block until the driver is in ``state``; False if it is not after ``timeout_s``."""
        with self._changed:
            return self._changed.wait_for(lambda: self._state is state, timeout_s)

    @property
    def state(self) -> TrackerState:
        return self._state

    def stats(self) -> TrackerStats:
        with self._changed:
            return self._stats

    # -- set-up ---------------------------------------------------------------------------------------------

    def _connect(self) -> None:
        self._close()
        self._serial = serial.Serial(self.port, POWER_UP_BAUDRATE, timeout=self.setup_timeout_s)
        try:
            self._okay("INIT:")
        except (TrackerLinkError, TrackerProtocolError) as first:
            if self.baudrate == POWER_UP_BAUDRATE:
                raise
            _log.info("tracker on %s: INIT at %d baud failed (%s); retrying at %d baud",
                      self.port, POWER_UP_BAUDRATE, first, self.baudrate)
            self._serial.baudrate = self.baudrate
            self._okay("INIT:")
        if self._serial.baudrate != self.baudrate:
            self._okay(f"COMM:{COMM_BAUD_CODES[self.baudrate]}0000")
            time.sleep(COMM_SETTLE_S)
            self._serial.baudrate = self.baudrate
        for entry in self._phsr("02"):
            self._okay(f"PINIT:{entry.handle:02X}")
        for entry in self._phsr("03"):
            self._okay(f"PENA:{entry.handle:02X}D")
        enabled = [entry.handle for entry in self._phsr("04")]
        if self.tool_handle not in enabled:
            listed = ", ".join(f"{handle:02X}" for handle in enabled) or "none"
            raise TrackerLinkError(f"port handle {self.tool_handle:02X} is not enabled after PINIT/PENA "
                                   f"(enabled: {listed}); is the sensor plugged into that port?")
        self._okay("TSTART:")

    def _okay(self, command: str) -> None:
        reply.parse_okay(self._command(command, self.setup_timeout_s), command)

    def _phsr(self, option: str) -> tuple[reply.PortHandle, ...]:
        return reply.parse_phsr(self._command(f"PHSR:{option}", self.setup_timeout_s))

    def _command(self, command: str, timeout_s: float) -> bytes:
        """Send one command (CRC added) and return the raw reply up to and including its CR."""
        if self._stop.is_set() and command != "TSTOP:":
            raise TrackerLinkError(f"{command} not sent: the driver is stopping")
        port = self._serial
        if port.timeout != timeout_s:
            port.timeout = timeout_s  # reconfigures the line (tcsetattr): only on a change
        try:
            port.reset_input_buffer()  # leftovers of an earlier failed exchange
        except termios.error as exc:  # pyserial lets tcflush's error through: the line has gone (EIO)
            raise serial.SerialException(f"{command} not sent: the serial line is gone ({exc})") from exc
        port.write(reply.with_crc(command))
        raw = _read_reply(port, timeout_s)
        if not raw.endswith(b"\r"):
            raise TrackerLinkError(f"no reply to {command} within {timeout_s} s (got {raw[:40]!r})")
        return raw

    def _close(self) -> None:
        if self._serial is not None:
            try:
                self._serial.close()
            except serial.SerialException as exc:
                _log.warning("tracker on %s: closing the port failed: %s", self.port, exc)
            self._serial = None

    # -- polling --------------------------------------------------------------------------------------------

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                self._poll()
            except _LINK_ERRORS as exc:
                if self._stop.is_set():
                    return  # stop() interrupted the exchange; it sends TSTOP and closes the port
                self._close()
                self._count(timeouts=isinstance(exc, TrackerLinkError))
                self._set_state(TrackerState.RECONNECTING, f"link lost: {exc}")
                self._reconnect()
                if self._serial is None:
                    return  # the port is gone for good, or stop() was called

    def _poll(self) -> None:
        """Poll TX until the link is lost (raises) or stop is requested: at rate_hz, or on demand once per
        request (a request made during an exchange gets the next one)."""
        bad_in_a_row = 0
        deadline_s = time.monotonic()
        while not self._stop.is_set():
            if self.period_s is None:
                self._wanted.wait()
                self._wanted.clear()
                if self._stop.is_set():
                    return
            sent_s = time.monotonic()
            raw = self._command("TX:0001", self.reply_timeout_s)
            t_s = time.monotonic()
            try:
                record = reply.parse_tx(raw).record(self.tool_handle)
            except reply.TrackerErrorReply:
                raise  # the device refuses TX: it left tracking mode, set it up again
            except TrackerProtocolError as exc:
                bad_in_a_row += 1
                crc = isinstance(exc, reply.TrackerCrcError)
                self._count(crc_errors=crc, bad_replies=not crc)
                _log.warning("tracker on %s: reply rejected (%d in a row): %s", self.port, bad_in_a_row, exc)
                if bad_in_a_row >= self.max_bad_replies:
                    raise TrackerProtocolError(f"{bad_in_a_row} unreadable replies in a row, last: {exc}") from exc
            else:
                bad_in_a_row = 0
                self._publish(t_s, record, sent_s)
            if self.period_s is None:
                if bad_in_a_row:
                    self._wanted.set()   # an unreadable reply answered no request: ask again
                continue
            deadline_s = max(deadline_s + self.period_s, time.monotonic())  # late: no catch-up burst
            self._stop.wait(deadline_s - time.monotonic())

    def _publish(self, t_s: float, record: reply.HandleRecord, sent_s: float) -> None:
        tip_mm = np.array(record.position_mm) if record.state is ToolState.VALID else None
        sample = TipSample(t_s, tip_mm, record.frame, record.port_status)
        with self._changed:
            self._latest = sample
            self._latest_sent_s = sent_s
            if tip_mm is not None:
                self._last_valid_t_s = t_s
            self._stats = _bump(self._stats, samples=True, missing=tip_mm is None)
            self._changed.notify_all()

    def _reconnect(self) -> None:
        wait_s = self.backoff_s
        while not self._stop.wait(wait_s):
            if not self._port_alive():
                self.last_error = f"{self.port} is gone for good: not opened again"
                self._set_state(TrackerState.STOPPED, self.last_error)
                return
            try:
                self._connect()
            except _LINK_ERRORS as exc:
                self._close()
                self.last_error = str(exc)
                _log.warning("tracker on %s: reconnection failed, next try in %.1f s: %s",
                             self.port, min(2 * wait_s, self.max_backoff_s), exc)
                wait_s = min(2 * wait_s, self.max_backoff_s)
                continue
            self._count(reconnects=True)
            self._set_state(TrackerState.TRACKING, "reconnected")
            return

    def _count(self, **flags: bool) -> None:
        with self._changed:
            self._stats = _bump(self._stats, **flags)

    def _set_state(self, state: TrackerState, reason: str) -> None:
        with self._changed:
            if state is TrackerState.RECONNECTING:
                self.last_error = reason
            self._state = state
            self._changed.notify_all()
        _log.info("tracker on %s: %s (%s)", self.port, state.value, reason)
        if self.on_state is not None:
            self.on_state(state, reason)


def _read_reply(port: serial.Serial, timeout_s: float) -> bytes:
    """The reply on ``port`` up to and including its CR (at most _MAX_REPLY_BYTES; shorter, without
    the CR, once ``timeout_s`` has passed). Takes what has arrived in one read, where pyserial's
    read_until reads byte by byte (a one-tool TX reply is 81 bytes); anything after the CR is dropped,
    as the next command's reset_input_buffer would drop it."""
    raw = bytearray()
    deadline_s = time.monotonic() + timeout_s
    while b"\r" not in raw and len(raw) < _MAX_REPLY_BYTES:
        chunk = port.read(max(1, min(port.in_waiting, _MAX_REPLY_BYTES - len(raw))))
        raw += chunk
        if not chunk or time.monotonic() > deadline_s:
            break
    end = raw.find(b"\r")
    return bytes(raw if end < 0 else raw[:end + 1])


def _bump(stats: TrackerStats, **flags: bool) -> TrackerStats:
    """``stats`` with each counter named in ``flags`` and set True incremented by one."""
    return TrackerStats(**{name: value + int(flags.get(name, False)) for name, value in vars(stats).items()})
