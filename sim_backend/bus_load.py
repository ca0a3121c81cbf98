"""CAN bus load: how long each frame occupies the wire, and whether a SYNC cycle fits.

Bits on the wire of a classical CAN frame with n data bytes (Davis, Burns, Bril,
Lukkien 2007, "Controller Area Network (CAN) schedulability analysis: refuted,
revisited and revised", eq. 1):

    standard (11-bit id):  47 + 8n + floor((34 + 8n - 1) / 4)
    extended (29-bit id):  67 + 8n + floor((54 + 8n - 1) / 4)

47 (67) bits are the frame's fixed fields including the 3-bit interframe space;
the floor term is the worst case of bit stuffing, one stuff bit per 4 bits over
the 34 (54) + 8n bits from start-of-frame to the end of the CRC. A remote frame
carries no data bytes (n = 0). An error frame takes at most 6 (error flag)
+ 6 (superposed flags of the other nodes) + 8 (delimiter) + 3 (intermission)
= 23 bits.

The time a frame occupies the bus is bits / bitrate. A SYNC cycle runs from one
SYNC frame (COB-ID 0x80) to the next; its load is the bus time of its frames
over the SYNC period. A cycle with load above 1 would not fit on a real bus at
that bitrate: the frames answering one SYNC would still be queued at the next.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import can

SYNC_COB_ID = 0x80
ERROR_FRAME_BITS = 23


def frame_bits(data_bytes: int, *, extended_id: bool = False) -> int:
    """Worst-case bits of a data (or, with data_bytes=0, remote) frame including interframe space."""
    if not 0 <= data_bytes <= 8:
        raise ValueError(f"a classical CAN frame carries 0..8 data bytes, got {data_bytes}")
    if extended_id:
        return 67 + 8 * data_bytes + (54 + 8 * data_bytes - 1) // 4
    return 47 + 8 * data_bytes + (34 + 8 * data_bytes - 1) // 4


def message_bits(message: can.Message) -> int:
    """Worst-case bits a python-can message occupies on the wire."""
    if message.is_error_frame:
        return ERROR_FRAME_BITS
    data_bytes = 0 if message.is_remote_frame else len(message.data)
    return frame_bits(data_bytes, extended_id=message.is_extended_id)


def is_sync(message: can.Message) -> bool:
    return (not message.is_error_frame and not message.is_extended_id
            and message.arbitration_id == SYNC_COB_ID and len(message.data) <= 1)


@dataclass(frozen=True)
class CycleLoad:
    """One SYNC cycle: its number (1 = the first SYNC), frames, bits and load (fraction of the period)."""

    cycle: int
    frames: int
    bits: int
    load: float


@dataclass(frozen=True)
class BusLoadReport:
    bitrate_bit_s: int
    sync_period_s: float
    cycles: int
    mean_load: float
    max_load: float
    overloaded: tuple[CycleLoad, ...]

    def __str__(self) -> str:
        text = (f"bus load at {self.bitrate_bit_s / 1000:g} kbit/s, SYNC period {self.sync_period_s * 1000:g} ms: "
                f"{self.cycles} cycles, mean {self.mean_load:.1%}, max {self.max_load:.1%}")
        if self.overloaded:
            worst = max(self.overloaded, key=lambda cycle: cycle.load)
            text += (f"; {len(self.overloaded)} cycles would not fit on a real bus "
                     f"(worst: cycle {worst.cycle}, {worst.frames} frames, {worst.bits} bits, {worst.load:.0%})")
        return text


class BusLoadMeter(can.Listener):
    """Accumulates frames per SYNC cycle; frames before the first SYNC are not in any cycle.

    Listen on a bus instance of its own (so it also sees the frames the drives send).
    """

    def __init__(self, bitrate_bit_s: int, sync_period_s: float) -> None:
        if bitrate_bit_s <= 0 or sync_period_s <= 0:
            raise ValueError(f"bus load needs bitrate > 0 and SYNC period > 0, got {bitrate_bit_s} bit/s, "
                             f"{sync_period_s} s")
        self.bitrate_bit_s = bitrate_bit_s
        self.sync_period_s = sync_period_s
        self._lock = threading.Lock()
        self._cycle = 0
        self._frames = 0
        self._bits = 0
        self._completed = 0
        self._load_sum = 0.0
        self._max_load = 0.0
        self._overloaded: list[CycleLoad] = []

    def _capacity_bits(self) -> float:
        return self.bitrate_bit_s * self.sync_period_s

    def on_message_received(self, msg: can.Message) -> None:
        with self._lock:
            if is_sync(msg):
                self._close_cycle()
                self._cycle += 1
            if self._cycle > 0:
                self._frames += 1
                self._bits += message_bits(msg)

    def _close_cycle(self) -> None:
        if self._cycle == 0:
            return
        cycle = self._current()
        self._completed += 1
        self._load_sum += cycle.load
        self._max_load = max(self._max_load, cycle.load)
        if cycle.load > 1.0:
            self._overloaded.append(cycle)
        self._frames = 0
        self._bits = 0

    def _current(self) -> CycleLoad:
        return CycleLoad(cycle=self._cycle, frames=self._frames, bits=self._bits,
                         load=self._bits / self._capacity_bits())

    def report(self) -> BusLoadReport:
        """All cycles so far; the running cycle counts with the frames seen up to now."""
        with self._lock:
            cycles, load_sum, max_load = self._completed, self._load_sum, self._max_load
            overloaded = list(self._overloaded)
            if self._cycle > 0:
                current = self._current()
                cycles += 1
                load_sum += current.load
                max_load = max(max_load, current.load)
                if current.load > 1.0:
                    overloaded.append(current)
            return BusLoadReport(bitrate_bit_s=self.bitrate_bit_s, sync_period_s=self.sync_period_s,
                                 cycles=cycles, mean_load=load_sum / cycles if cycles else 0.0,
                                 max_load=max_load, overloaded=tuple(overloaded))

    def stop(self) -> None:
        """Listener interface: nothing to release."""
