"""The host's view of the drives' NMT error control messages (CiA 301): boot-up and heartbeat.

Both arrive on COB-ID 0x700 + node id with one byte: 0x00 boot-up (sent once after power-on
or an NMT reset), otherwise the heartbeat with the NMT state (0x04 STOPPED, 0x05 OPERATIONAL,
0x7F PRE-OPERATIONAL), every 0x1017 ms of the drive.

Reception times are taken from the driver's clock, so heartbeat loss is judged in the same
time as the SYNC cycle (wall time on hardware, simulated time on a stepped virtual testbed).
"""

from __future__ import annotations

import threading
from collections.abc import Mapping

import canopen

from crest.driver.clock import Clock

BOOT_UP = 0x00
NMT_STATE_NAMES = {0x00: "BOOT-UP", 0x04: "STOPPED", 0x05: "OPERATIONAL", 0x7F: "PRE-OPERATIONAL"}


class HeartbeatConsumer:
    """Boot-up messages and heartbeats of the drives ``{node id: axis name}``."""

    def __init__(self, network: canopen.Network, clock: Clock, axes_by_node: Mapping[int, str],
                 timeout_s: float) -> None:
        self._clock = clock
        self._axes_by_node = dict(axes_by_node)
        self.timeout_s = timeout_s
        self._changed = threading.Condition()
        self._booted: set[str] = set()
        self._nmt_state: dict[str, int] = {}
        self._last_seen_s: dict[str, float] = {}
        for node_id in self._axes_by_node:
            network.subscribe(0x700 + node_id, self._on_message)

    def _on_message(self, can_id: int, data: bytearray, timestamp: float) -> None:
        if not data:
            return
        axis = self._axes_by_node[can_id - 0x700]
        with self._changed:
            self._nmt_state[axis] = data[0]
            if data[0] == BOOT_UP:
                self._booted.add(axis)
            elif axis in self._last_seen_s:
                self._last_seen_s[axis] = self._clock.now_s()
            self._changed.notify_all()

    # --- boot-up -----------------------------------------------------------------------
    def forget_boot_ups(self) -> None:
        """Call before sending NMT reset: only boot-ups after it count."""
        with self._changed:
            self._booted.clear()

    def wait_for_boot_ups(self, timeout_s: float) -> list[str]:
        """Wait (wall time) until every drive has booted; returns the axes that have not."""
        with self._changed:
            self._changed.wait_for(lambda: len(self._booted) == len(self._axes_by_node), timeout=timeout_s)
            return [axis for axis in self._axes_by_node.values() if axis not in self._booted]

    # --- heartbeat -----------------------------------------------------------------------
    def start_watching(self) -> None:
        """Heartbeat monitoring starts now: each drive has ``timeout_s`` for its next heartbeat."""
        now_s = self._clock.now_s()
        with self._changed:
            self._last_seen_s = {axis: now_s for axis in self._axes_by_node.values()}

    def stop_watching(self) -> None:
        with self._changed:
            self._last_seen_s = {}

    def silent_axes(self, now_s: float, longer_than_s: float | None = None) -> list[tuple[str, float]]:
        """(axis, seconds since its last heartbeat), the longest silence first, for every watched
        drive silent longer than ``longer_than_s`` (default: the timeout)."""
        limit_s = self.timeout_s if longer_than_s is None else longer_than_s
        with self._changed:
            silences = [(axis, now_s - seen_s) for axis, seen_s in self._last_seen_s.items() if now_s - seen_s > limit_s]
        return sorted(silences, key=lambda silence: -silence[1])

    def nmt_state(self, axis: str) -> str:
        """The NMT state of the drive's last boot-up or heartbeat ("UNKNOWN" if none was seen)."""
        with self._changed:
            code = self._nmt_state.get(axis)
        return "UNKNOWN" if code is None else NMT_STATE_NAMES.get(code, f"0x{code:02X}")
