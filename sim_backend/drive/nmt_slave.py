"""NMT slave of a simulated drive: states, boot-up and a heartbeat producer driven by ``tick``.

CiA 301 NMT (section 7.2.8.3): after power-on or a reset the node sends the
boot-up message (COB-ID 0x700 + node id, one byte 0x00) and enters
PRE-OPERATIONAL on its own. Commands on COB-ID 0x000 ([command, node id],
node id 0 = all nodes): 0x01 start (OPERATIONAL), 0x02 stop (STOPPED),
0x80 enter PRE-OPERATIONAL, 0x81 reset node, 0x82 reset communication.
The heartbeat (same COB-ID, one byte: 0x04 stopped, 0x05 operational,
0x7F pre-operational) is sent every 0x1017 ms.

canopen's NmtSlave sends the heartbeat from a python-can periodic task (wall
clock) and, on a *received* reset command, neither sends the boot-up message
nor re-enters PRE-OPERATIONAL. This subclass keeps its state handling and
0x1017 write hook, and instead produces the heartbeat when ``tick(now_s)`` is
called and runs the reset sequence through a callback to the drive.
"""

from __future__ import annotations

import struct
from typing import Callable

from canopen.nmt import NmtSlave

from sim_backend.sim_time import whole_us

BOOT_UP_STATE = 0x00
PRE_OPERATIONAL = 127
OPERATIONAL = 5
STOPPED = 4

START_REMOTE_NODE = 0x01
STOP_REMOTE_NODE = 0x02
ENTER_PRE_OPERATIONAL = 0x80
RESET_NODE = 0x81
RESET_COMMUNICATION = 0x82

_STATE_OF_COMMAND = {
    START_REMOTE_NODE: OPERATIONAL,
    STOP_REMOTE_NODE: STOPPED,
    ENTER_PRE_OPERATIONAL: PRE_OPERATIONAL,
}


class TickedNmtSlave(NmtSlave):
    """NMT state machine and heartbeat producer stepped by an injected clock.

    ``on_reset(command)`` is called for reset node / reset communication before
    the boot-up message, so the drive can restore its object dictionary.
    ``send(cob_id, data)`` transmits a frame (the drive gates it when silent).
    """

    def __init__(self, node_id: int, local_node,
                 on_reset: Callable[[int], None], send: Callable[[int, bytes], None]) -> None:
        super().__init__(node_id, local_node)
        self._on_reset = on_reset
        self._send = send
        self._last_heartbeat_s: float | None = None

    @property
    def state_code(self) -> int:
        """The NMT state as sent in the heartbeat (0x04, 0x05 or 0x7F)."""
        return self._state

    def boot_up(self) -> None:
        """Send the boot-up message and enter PRE-OPERATIONAL (CiA 301 initialisation end)."""
        self._state = BOOT_UP_STATE
        self._send(0x700 + self.id, bytes([BOOT_UP_STATE]))
        self._state = PRE_OPERATIONAL
        self._last_heartbeat_s = None

    def on_command(self, can_id: int, data: bytes, timestamp: float) -> None:
        """Handle an NMT command frame addressed to this node or to all nodes."""
        if len(data) < 2:
            return
        command, node_id = struct.unpack_from("BB", data)
        if node_id not in (0, self.id):
            return
        if command in (RESET_NODE, RESET_COMMUNICATION):
            self._state = BOOT_UP_STATE
            self._on_reset(command)
            self.boot_up()
        elif command in _STATE_OF_COMMAND:
            self._state = _STATE_OF_COMMAND[command]

    def start_heartbeat(self, heartbeat_time_ms: int) -> None:
        """Called for writes of 0x1017: only the period changes; ``tick`` sends."""
        self._heartbeat_time_ms = heartbeat_time_ms

    def stop_heartbeat(self) -> None:
        self._heartbeat_time_ms = 0

    def update_heartbeat(self) -> None:
        """The heartbeat is built from the current state when sent; nothing to update."""

    def tick(self, now_s: float) -> None:
        """Send the heartbeat if one producer period has passed since the last one (compared in
        whole microseconds, sim_backend.sim_time)."""
        if self._heartbeat_time_ms <= 0 or self._state == BOOT_UP_STATE:
            return
        if self._last_heartbeat_s is None:
            self._last_heartbeat_s = now_s
            return
        if whole_us(now_s - self._last_heartbeat_s) >= self._heartbeat_time_ms * 1000:
            self._last_heartbeat_s = now_s
            self._send(0x700 + self.id, bytes([self._state]))
