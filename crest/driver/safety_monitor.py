"""The safety monitor: the first stop cause wins and quick-stops every axis at once.

Causes arrive from two threads: the CAN notifier (EMCY, error frames) and the thread running
the SYNC cycle (heartbeat loss, process data checks, SDO failures, Ctrl-C, exceptions).
``trip`` keeps the first cause and calls ``quick_stop_all`` in the calling thread before it
returns, so the quick-stop controlwords are on the bus before the next SYNC: every axis starts
its quick stop within one SYNC period of the detection. The rest of the stop (ramp, disable,
callbacks, SafetyStop) is finished by the cycle thread.
"""

from __future__ import annotations

import threading
from typing import Callable

import can
from canopen.emcy import EmcyError

from crest.driver.errors import StopCause
from crest.driver.stop_causes import emcy_cause, error_frame_cause


class SafetyMonitor:
    """Keeps the first StopCause; bus events count only while ``armed`` (after boot)."""

    def __init__(self, quick_stop_all: Callable[[], None]) -> None:
        self._quick_stop_all = quick_stop_all
        self._lock = threading.Lock()
        self._cause: StopCause | None = None
        self.armed = False

    @property
    def cause(self) -> StopCause | None:
        with self._lock:
            return self._cause

    def trip(self, cause: StopCause) -> None:
        """Record ``cause`` unless a cause is already recorded; the first one quick-stops every axis."""
        with self._lock:
            if self._cause is not None:
                return
            self._cause = cause
        self._quick_stop_all()

    def emcy_listener(self, axis: str) -> Callable[[EmcyError], None]:
        """A canopen EMCY callback for ``axis``: any error code but 0x0000 (error reset) trips."""
        def on_emcy(emcy: EmcyError) -> None:
            if self.armed and emcy.code & 0xFF00:
                self.trip(emcy_cause(axis, emcy.code))
        return on_emcy


class ErrorFrameListener(can.Listener):
    """python-can listener: any CAN error frame (error counters rising, bus-off) trips the monitor.

    canopen's own listener drops error frames, so this one sits next to it on the notifier.
    """

    def __init__(self, monitor: SafetyMonitor) -> None:
        self._monitor = monitor

    def on_message_received(self, msg: can.Message) -> None:
        if msg.is_error_frame and self._monitor.armed:
            self._monitor.trip(error_frame_cause(msg))

    def stop(self) -> None:
        """Listener interface: nothing to release."""
