"""Record the CAN traffic of a run beside its log, with python-can's own writers (.blf or .asc).

The file is written by ``can.Logger`` (``can.BLFWriter`` / ``can.ASCWriter``), so it replays
with python-can's tools (``can.LogReader``, ``python -m can.player``, ``python -m can.logconvert``)
and opens in Vector tools. It is complete once `BusRecorder.close` has run; .blf buffers
compressed containers in memory, .asc goes through a normal file buffer.

A bus handle does not receive the frames it sends itself. To record the host's own frames too,
record from a second handle on the same channel (the virtual interface and socketcan deliver
every frame to every handle), or open the driver's bus with ``receive_own_messages=True``.
"""

from __future__ import annotations

import threading
import time
import warnings
from pathlib import Path
from types import TracebackType

import can

RECORD_SUFFIXES = (".blf", ".asc")


class BusRecorder(can.Listener):
    """A python-can listener writing every received frame to ``path`` (.blf or .asc).

    Either `attach` it to an existing ``can.Notifier`` (e.g. canopen's ``network.notifier``: a
    bus may have only one active notifier), or let it `listen` to a bus with its own notifier.
    """

    def __init__(self, path: Path | str) -> None:
        self.path = Path(path)
        if self.path.suffix.lower() not in RECORD_SUFFIXES:
            raise ValueError(f"{self.path}: record CAN traffic to a {' or '.join(RECORD_SUFFIXES)} file, "
                             "which python-can's tools replay")
        self._lock = threading.Lock()
        self._writer: can.io.generic.MessageWriter | None = can.Logger(self.path)
        self._notifier: can.Notifier | None = None
        self._own_notifier = False
        self.frames_recorded = 0
        self.error: Exception | None = None

    def attach(self, notifier: can.Notifier) -> None:
        """Record what ``notifier`` distributes (its bus or buses)."""
        self._set_notifier(notifier, own=False)
        notifier.add_listener(self)

    def listen(self, bus: can.BusABC) -> None:
        """Record ``bus`` through a notifier of our own (the bus must not have another one)."""
        # A short receive timeout lets close() stop the notifier's thread within 0.1 s.
        self._set_notifier(can.Notifier(bus, [self], timeout=0.1), own=True)

    def _set_notifier(self, notifier: can.Notifier, *, own: bool) -> None:
        if self._notifier is not None:
            raise RuntimeError(f"{self.path}: the recorder is already attached; use one recorder per source")
        self._notifier = notifier
        self._own_notifier = own

    def on_message_received(self, msg: can.Message) -> None:
        """Write one frame. A writer failure ends the recording (kept in `error`, with a warning) but is
        never raised: the notifier's thread also feeds the driver, and dies on a listener's exception."""
        with self._lock:
            if self._writer is None or self.error is not None:
                return
            try:
                self._writer.on_message_received(msg)
            except Exception as error:  # noqa: BLE001 - any writer failure must stay out of the rx thread
                self.error = error
                warnings.warn(f"{self.path}: CAN recording stopped after {self.frames_recorded} frames: "
                              f"{type(error).__name__}: {error}", RuntimeWarning, stacklevel=2)
                return
            self.frames_recorded += 1

    def stop(self) -> None:
        """python-can's Listener.stop: the same as `close`."""
        self.close()

    def close(self) -> None:
        """Detach from the notifier and finish the file (writes the .blf header and last container)."""
        notifier, self._notifier = self._notifier, None
        if notifier is not None:
            if self._own_notifier:
                notifier.remove_listener(self)   # its stop() would close the file before the drain
                notifier.stop()
                self._drain(notifier.bus)
            elif not notifier.stopped and self in notifier.listeners:
                # A stopping notifier is iterating its listeners (calling our stop): leave its list alone.
                notifier.remove_listener(self)
        with self._lock:
            writer, self._writer = self._writer, None
            if writer is not None:
                writer.stop()

    def _drain(self, bus: can.BusABC) -> None:
        """Record the frames ``bus`` received before now that the notifier's thread had not handed on
        (e.g. the last frames of a safety stop, when the stop callback closes the recording)."""
        now_s = time.time()   # python-can timestamps frames in time.time() seconds
        while (msg := bus.recv(0)) is not None and msg.timestamp <= now_s:
            self.on_message_received(msg)

    def __enter__(self) -> BusRecorder:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 traceback: TracebackType | None) -> None:
        self.close()
