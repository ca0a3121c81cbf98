"""The host's heartbeat (CiA 301 NMT error control): COB-ID 0x700 + master node id, one byte 0x05.

The drives consume it (their 0x1016 names the master node id and a consumer time). The
heartbeat is sent from the control cycle, not from a thread of its own, so it stops when the
host stops cycling: a killed or hung host is a silent master, and every drive stops itself
once its consumer time has passed.
"""

from __future__ import annotations

import canopen

OPERATIONAL = 0x05
#: Times summed from SYNC periods carry float rounding; a heartbeat due within this is due now.
TIME_RESOLUTION_S = 1e-6


class HeartbeatProducer:
    """Sends the host heartbeat when ``poll(now_s)`` finds a period has passed since the last one."""

    def __init__(self, network: canopen.Network, node_id: int, period_s: float) -> None:
        self._network = network
        self.cob_id = 0x700 + node_id
        self.period_s = period_s
        self._last_sent_s: float | None = None

    def poll(self, now_s: float) -> None:
        if self._last_sent_s is None or now_s - self._last_sent_s >= self.period_s - TIME_RESOLUTION_S:
            self._network.send_message(self.cob_id, bytes([OPERATIONAL]))
            self._last_sent_s = now_s
