"""The host's own handle on the CAN bus, which shows every frame it sends and receives to hooks.

Whoever wants the whole traffic of a run (the bus recording beside the log, the bench's bus-load
meter) taps the host's own handle instead of opening a second one: on hardware a second handle
would not see the host's frames (a CAN socket does not receive what it sends); on a served
testbed it would be a second connection, for which the testbed sends every frame twice; in one
process it would be one more receiving thread. The same wrapper serves every bus (hardware, the
in-process virtual bus, the served testbed's connection), so what is recorded does not depend on
where the drives are.

A hook runs in the thread that sends or receives the frame (the SYNC cycle, the bus's receiving
thread): it must be quick and must not raise (hand the frame to a queue, count its bits).

A frame sent is shown as a copy with the time it left (``time.time()``, the clock of python-can's
received timestamps) and ``is_rx`` False (a recording marks it transmitted); a received frame as
the bus stamped it.
"""
from __future__ import annotations

import copy
import time
from collections.abc import Callable

import can

Hook = Callable[[can.Message], None]


class HookedBus(can.BusABC):
    """``bus``, with ``send_hooks`` and ``receive_hooks`` that see every frame it sends and receives."""

    def __init__(self, bus: can.BusABC) -> None:
        self.inner = bus
        self.send_hooks: list[Hook] = []
        self.receive_hooks: list[Hook] = []
        super().__init__(channel=bus.channel_info)
        self.channel_info = bus.channel_info

    def tap(self, hook: Hook) -> None:
        """`hook` sees every frame sent and received from now on. The lists are replaced, not changed,
        so a thread going through them meanwhile sees them whole, before or after."""
        self.send_hooks = [*self.send_hooks, hook]
        self.receive_hooks = [*self.receive_hooks, hook]

    def untap(self, hook: Hook) -> None:
        self.send_hooks = [h for h in self.send_hooks if h != hook]
        self.receive_hooks = [h for h in self.receive_hooks if h != hook]

    def _recv_internal(self, timeout: float | None) -> tuple[can.Message | None, bool]:
        msg = self.inner.recv(timeout)      # filtered by the inner bus
        if msg is not None:
            for hook in self.receive_hooks:
                hook(msg)
        return msg, True

    def send(self, msg: can.Message, timeout: float | None = None) -> None:
        self.inner.send(msg, timeout)
        if self.send_hooks:
            sent = copy.copy(msg)
            sent.timestamp, sent.is_rx = time.time(), False
            for hook in self.send_hooks:
                hook(sent)

    def shutdown(self) -> None:
        self.inner.shutdown()
        super().shutdown()
