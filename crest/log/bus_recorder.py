"""Record the CAN traffic of a run beside its log, with python-can's own writers (.blf or .asc).

The file is written by ``can.Logger`` (``can.BLFWriter`` / ``can.ASCWriter``), so it replays
with python-can's tools (``can.LogReader``, ``python -m can.player``, ``python -m can.logconvert``)
and opens in Vector tools. It is complete once `BusRecorder.close` has run; .blf buffers
compressed containers in memory, .asc goes through a normal file buffer.

The recorder is handed its frames by the host's own bus handle (crest.driver.hooked_bus: what the
host sends and what it receives), in the thread that sent or received each one: the SYNC cycle's
among them. So `on_message_received` only queues the frame; a thread of the recorder's own writes
the queue out every ``WRITE_PERIOD_S`` (a .blf container's compression takes milliseconds, the
disk may take longer), and `close` writes what is left.
"""

from __future__ import annotations

import queue
import threading
import warnings
from pathlib import Path
from types import TracebackType

import can

RECORD_SUFFIXES = (".blf", ".asc")
WRITE_PERIOD_S = 0.05   # how long frames may wait in the queue before they are written


class BusRecorder(can.Listener):
    """A python-can listener writing every frame it is handed to ``path`` (.blf or .asc)."""

    def __init__(self, path: Path | str) -> None:
        self.path = Path(path)
        if self.path.suffix.lower() not in RECORD_SUFFIXES:
            raise ValueError(f"{self.path}: record CAN traffic to a {' or '.join(RECORD_SUFFIXES)} file, "
                             "which python-can's tools replay")
        self._writer: can.io.generic.MessageWriter | None = can.Logger(self.path)
        self._frames: queue.SimpleQueue[can.Message] = queue.SimpleQueue()
        self._closing = threading.Event()
        self._close_lock = threading.Lock()
        self.frames_recorded = 0
        self.error: Exception | None = None
        self._thread = threading.Thread(target=self._write_periodically, name=f"bus recorder {self.path.name}",
                                        daemon=True)
        self._thread.start()

    def on_message_received(self, msg: can.Message) -> None:
        """Queue one frame (any thread; never blocks, never raises)."""
        self._frames.put(msg)

    def _write_periodically(self) -> None:
        while not self._closing.wait(WRITE_PERIOD_S):
            self._write_queued()

    def _write_queued(self) -> None:
        """Write what is queued. A writer failure ends the recording (kept in `error`, with a warning)
        and the frames after it are dropped; the run goes on."""
        while True:
            try:
                msg = self._frames.get_nowait()
            except queue.Empty:
                return
            if self._writer is None or self.error is not None:
                continue
            try:
                self._writer.on_message_received(msg)
            except Exception as error:  # noqa: BLE001 - a writer failure must not end the run
                self.error = error
                warnings.warn(f"{self.path}: CAN recording stopped after {self.frames_recorded} frames: "
                              f"{type(error).__name__}: {error}", RuntimeWarning, stacklevel=2)
                continue
            self.frames_recorded += 1

    def stop(self) -> None:
        """python-can's Listener.stop: the same as `close`."""
        self.close()

    def close(self) -> None:
        """Write the frames handed so far and finish the file (the .blf header and last container).
        Frames handed later are not recorded. Safe to call twice and from any thread."""
        with self._close_lock:
            if self._writer is None:
                return
            self._closing.set()
            self._thread.join()
            self._write_queued()
            writer, self._writer = self._writer, None
            writer.stop()

    def __enter__(self) -> BusRecorder:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 traceback: TracebackType | None) -> None:
        self.close()
