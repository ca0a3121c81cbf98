"""Simulated time on the bus: CANopen TIME stamps (CiA 301, COB-ID 0x100) that move a virtual testbed's clock.

A virtual testbed served in simulated time (`crest testbed serve --simulated-time`) has no clock of
its own. Its master's stepped clock sends a TIME stamp each time it moves, and the testbed moves its
drives' heartbeats and watchdogs, and its scheduled faults, to the time the stamp carries, before it
handles the next frame. The drives' receive thread handles frames in order, so a SYNC that follows
a stamp finds the testbed at that time, as a testbed ticked inside the master's process would be.

The frame is the standard one, 6 bytes, little-endian:

    bytes 0-3  milliseconds after midnight (the upper 4 bits zero)
    bytes 4-5  days since 1984-01-01

Here "midnight of day 0" is the testbed's start, so a stamp carries t_ms = round(1000 t_s) as
days = t_ms // 86 400 000 and ms = t_ms mod 86 400 000: the clock moves in whole milliseconds.

The testbed answers each stamp, once its drives are at that time, with the same 6 bytes on
TIME_ACK_COB_ID (0x101, unused in CANopen's predefined connection set; the virtual testbed's own,
not a CANopen service). Before the master sends a stamp it waits for the answer to the one before
(`StampAnswers`): the frames the drives sent up to that time (their heartbeats) are then in, so a
heartbeat watch in simulated time runs at most one clock step (a SYNC period or a tracker frame)
ahead of the heartbeats, never a heartbeat timeout. The wait costs nothing in a cycle, whose TPDOs
come after the answer. A testbed that does not answer within the wait is taken as gone: the
master stops waiting (until it answers again) and its heartbeat watch, in simulated time, finds
the drives silent.

A command's `--fault` times count from the start of its motion. In simulated time the command says
when that is with a FAULT_CLOCK_COB_ID frame (0x102, no data; the virtual testbed's own too) on the
bus, right after the stamp of that moment, so the testbed starts the fault clock at the time of the
stamp before it, in order with the stamps, as a testbed inside the command's process would.
"""
from __future__ import annotations

import struct
import sys
import threading
import time
from collections.abc import Callable

import can

TIME_COB_ID = 0x100
TIME_ACK_COB_ID = 0x101
FAULT_CLOCK_COB_ID = 0x102
MS_PER_DAY = 86_400_000
POLL_S = 0.1        # how often a wait looks whether the bus is gone


def time_stamp_frame(now_s: float) -> can.Message:
    """The TIME stamp that moves a testbed to now_s (s since its start, >= 0)."""
    total_ms = int(round(now_s * 1000.0))
    if total_ms < 0:
        raise ValueError(f"a simulated time cannot be negative: {now_s} s")
    days, ms = divmod(total_ms, MS_PER_DAY)
    return can.Message(arbitration_id=TIME_COB_ID, is_extended_id=False, data=struct.pack("<IH", ms, days))


def time_stamp_seconds(data: bytes) -> float:
    """The time (s since the testbed's start) a TIME stamp's 6 data bytes carry."""
    if len(data) != 6:
        raise ValueError(f"a TIME stamp has 6 data bytes, got {len(data)}")
    ms, days = struct.unpack("<IH", bytes(data))
    return (days * MS_PER_DAY + (ms & 0x0FFFFFFF)) / 1000.0


def time_ack_frame(data: bytes) -> can.Message:
    """The testbed's answer to the TIME stamp with these data bytes."""
    return can.Message(arbitration_id=TIME_ACK_COB_ID, is_extended_id=False, data=bytes(data))


def fault_clock_frame() -> can.Message:
    """The frame that starts a testbed's fault clock at the time of the last stamp."""
    return can.Message(arbitration_id=FAULT_CLOCK_COB_ID, is_extended_id=False, data=b"")


def follow_time_stamps(drives, tick: Callable[[float], None],
                       start_fault_clock: Callable[[], None] = lambda: None) -> None:
    """The testbed's side: each TIME stamp on the bus of `drives` (a SimDriveSet, started) calls
    tick(now_s), then is answered, and a fault clock frame calls start_fault_clock(); in the drives'
    receive thread, so in order with their frames."""
    def on_stamp(can_id: int, data: bytearray, timestamp: float) -> None:
        try:
            now_s = time_stamp_seconds(data)
        except ValueError as exc:       # a frame some other node sent with this COB-ID
            print(f"virtual testbed: TIME stamp ignored: {exc}", file=sys.stderr, flush=True)
            return
        tick(now_s)
        drives.send(time_ack_frame(data))

    drives.subscribe(TIME_COB_ID, on_stamp)
    drives.subscribe(FAULT_CLOCK_COB_ID, lambda can_id, data, timestamp: start_fault_clock())


class StampAnswers:
    """The master's side: the latest time the testbed answered, and a wait for an answer.

    Give every frame the master's bus receives to `on_frame` (its receive thread); `sent` and the
    waits from the thread that sends the stamps."""

    def __init__(self) -> None:
        self._answered_s = -1.0
        self._sent_s: float | None = None
        self._answering = True      # False after a wait ran out, until the next answer
        self._changed = threading.Condition()

    def sent(self, now_s: float) -> None:
        """The stamp of now_s went out."""
        self._sent_s = now_s

    def wait_for_last(self, timeout_s: float, gone: Callable[[], bool]) -> bool:
        """`wait` for the answer to the last stamp sent (True at once if none was)."""
        return True if self._sent_s is None else self.wait(self._sent_s, timeout_s, gone)

    def on_frame(self, msg: can.Message) -> None:
        if msg.arbitration_id == TIME_ACK_COB_ID and len(msg.data) == 6:
            with self._changed:
                self._answered_s = max(self._answered_s, time_stamp_seconds(msg.data))
                self._answering = True
                self._changed.notify_all()

    def wait(self, now_s: float, timeout_s: float, gone: Callable[[], bool]) -> bool:
        """Wait until the stamp of now_s is answered (True), the testbed is gone, or timeout_s of
        wall time pass (False both; once a wait ran out, later ones do not wait for a testbed that
        stopped answering)."""
        wanted_s = round(now_s * 1000.0) / 1000.0
        deadline_s = time.monotonic() + timeout_s
        with self._changed:
            while self._answered_s < wanted_s:
                remaining_s = deadline_s - time.monotonic()
                if not self._answering or gone() or remaining_s <= 0.0:
                    self._answering = False
                    return False
                self._changed.wait(min(POLL_S, remaining_s))
            return True
