"""Heartbeat consumer of a drive (CiA 301 object 0x1016).

Each 0x1016 entry is a UNSIGNED32: bits 16-23 the producer's node id, bits 0-15
the consumer heartbeat time in ms (0 or node id 0: entry unused). Monitoring of
a producer starts with its first heartbeat; when no further heartbeat arrives
within the consumer time, a heartbeat event occurs (the drive answers with EMCY
0x8130 and a fault). After an event, monitoring restarts with the next heartbeat.

The consumer reads no clock: the drive marks receptions, and ``tick(now_s)``
turns them into times.
"""

from __future__ import annotations

from sim_backend.sim_time import whole_us


def decode_consumer_entry(entry: int) -> tuple[int, float]:
    """(producer node id, consumer time in s) of a 0x1016 sub-entry."""
    return (entry >> 16) & 0x7F, (entry & 0xFFFF) / 1000.0


class HeartbeatConsumer:
    """Watches one producer (the master)."""

    def __init__(self) -> None:
        self.configure(0)

    def configure(self, entry: int) -> None:
        """Take a 0x1016 entry; monitoring waits for the first heartbeat again."""
        self.producer_node_id, self.timeout_s = decode_consumer_entry(entry)
        self._received = False
        self._last_seen_s: float | None = None

    @property
    def enabled(self) -> bool:
        return self.producer_node_id != 0 and self.timeout_s > 0.0

    def on_heartbeat(self) -> None:
        """A heartbeat of the producer was received (time assigned at the next tick)."""
        self._received = True

    def tick(self, now_s: float) -> bool:
        """True exactly once when the producer's heartbeat has been missing longer than the timeout
        (compared in whole microseconds, sim_backend.sim_time)."""
        if not self.enabled:
            return False
        if self._received:
            self._received = False
            self._last_seen_s = now_s
            return False
        if self._last_seen_s is not None and whole_us(now_s - self._last_seen_s) > whole_us(self.timeout_s):
            self._last_seen_s = None
            return True
        return False
