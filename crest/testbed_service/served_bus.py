"""The host's handle on a served virtual testbed's CAN bus: python-can-remote's bus, made to fail
the way a CAN bus fails.

When the testbed's process ends (stopped, or killed), python-can-remote's `RemoteBus` raises its own
`WebsocketClosed` (or an OSError, or a ValueError on the closed socket) from ``recv``, ``send`` and
``shutdown``. On a CAN bus, drives that lose power simply fall silent. This handle does the same:
after the connection is lost, ``recv`` returns nothing, ``send`` goes to nobody, and ``shutdown``
succeeds. The master then sees every drive's heartbeat stop and makes its safety stop, exactly as
it would on hardware; `lost` keeps what ended the connection.
"""
from __future__ import annotations

import threading

import can
from can_remote.client import RemoteBus
from can_remote.websocket import WebsocketClosed

CONNECTION_ERRORS = (WebsocketClosed, OSError, ValueError)   # ValueError: select() on the closed socket


class ServedBus(RemoteBus):
    """`can.Bus(interface="remote", channel=url)`, silent instead of raising once the server is gone."""

    def __init__(self, channel: str, **config) -> None:
        self.lost: Exception | None = None
        self._closed = threading.Event()
        super().__init__(channel, **config)

    def recv(self, timeout: float | None = None) -> can.Message | None:
        if self.lost is None:
            try:
                msg = super().recv(timeout)
            except CONNECTION_ERRORS as exc:
                self.lost = exc
            else:
                return msg
        self._closed.wait(timeout)
        return None

    def send(self, msg: can.Message, timeout: float | None = None) -> None:
        if self.lost is None:
            try:
                super().send(msg, timeout)
            except CONNECTION_ERRORS as exc:
                self.lost = exc

    def shutdown(self) -> None:
        self._closed.set()
        if self.lost is None and not self._is_shutdown:
            try:
                super().shutdown()
                return
            except CONNECTION_ERRORS as exc:
                self.lost = exc
        can.BusABC.shutdown(self)
