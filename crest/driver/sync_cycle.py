"""One SYNC cycle on the bus: host heartbeat, RPDO1 to every drive, SYNC, TPDO1 from every drive.

The cycle is paced by the driver's clock at the configured SYNC period (CiA 301 SYNC, COB-ID
0x80, no counter byte). The drives latch the set-points at the SYNC and answer it with their
TPDO1, sampled at that SYNC; ``run`` returns when every drive has answered or the reply time
has passed (a drive that did not answer is marked not fresh, its heartbeat decides whether it
is lost). Work that does not need this SYNC's replies (``meanwhile``, e.g. the next set-point of
a feedforward controller) runs after the SYNC is sent, while the drives answer it.

A TPDO1 carries no SYNC counter, so a reply that comes after its cycle gave up on it would pass
for the next SYNC's answer, and a log row would hold the drive's state of one SYNC earlier. So a
drive that did not answer owes that reply: in the next cycle its first TPDO1 pays the debt (the
late answer, not fresh), and only a second one answers the new SYNC. A debt is one reply at most,
and one the next cycle cannot settle is dropped: after a reply that never comes (a dropped frame,
a drive that fell silent), the drive is in step again a cycle later, not behind for good.

``first_reply_timeout_s`` is the patience for the first reply of a SYNC from any drive, where it
is longer than ``reply_timeout_s`` (simulated time: the drives' process only answers late when
its host is busy, since the testbed's time waits for the SYNCs). Once one drive has answered, the
others get ``reply_timeout_s``, and a cycle in which no drive answered at all is followed by one
with the ordinary patience (a testbed that is gone is found by the heartbeats, not waited for).

``answer_latency`` keeps, in wall time, how long each cycle's answers took (answer_latency), and
``timing`` when each SYNC left (sync_timing).

``quick_stop_all`` may be called from any thread: under the send lock it replaces every
controlword by quick stop, sends it to every drive at once, and keeps sending it in every
later cycle.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Sequence

import can
import canopen

from crest.driver import cia402
from crest.driver.answer_latency import AnswerLatency
from crest.driver.clock import Clock
from crest.driver.drive_axis import DriveAxis
from crest.driver.heartbeat_producer import HeartbeatProducer
from crest.driver.sync_timing import SyncTiming

SYNC_COB_ID = 0x80


class SyncCycle:
    """The bus side of the control cycle for ``axes``.

    :param reply_timeout_s: wall time to wait for the TPDOs after a SYNC.
    :param first_reply_timeout_s: wall time to wait for the first of them (module doc); at most
        ``reply_timeout_s`` means no extra patience.
    """

    def __init__(self, network: canopen.Network, clock: Clock, axes: Sequence[DriveAxis], period_s: float,
                 heartbeat: HeartbeatProducer, feedback_changed: threading.Condition,
                 reply_timeout_s: float, first_reply_timeout_s: float = 0.0) -> None:
        self._network = network
        self._clock = clock
        self.axes = tuple(axes)
        self.period_s = period_s
        self._heartbeat = heartbeat
        self._feedback_changed = feedback_changed
        self.reply_timeout_s = reply_timeout_s
        self.first_reply_timeout_s = first_reply_timeout_s
        self._late_reply_at: list[int | None] = [None] * len(self.axes)   # tpdo_count once an owed reply came
        self._any_reply_last_cycle = True
        self._send_lock = threading.Lock()
        self._override: int | None = None
        self.next_sync_s: float | None = None
        self.count = 0
        self.send_failures: list[str] = []
        self.answer_latency = AnswerLatency()
        self.timing = SyncTiming(period_s)

    @property
    def started(self) -> bool:
        return self.next_sync_s is not None

    def run(self, meanwhile: Callable[[], None] | None = None) -> tuple[float, tuple[bool, ...]]:
        """Wait for the SYNC time, send, call ``meanwhile``, wait for the replies; (SYNC time s,
        fresh TPDO1 per axis)."""
        if self.next_sync_s is None:
            self.next_sync_s = self._clock.now_s()
        ready_in_time = self._clock.now_s() < self.next_sync_s
        self._clock.wait_until(self.next_sync_s)
        now_s = self._clock.now_s()
        self.next_sync_s = self._following_sync_s(now_s)
        self._heartbeat.poll(now_s)
        with self._feedback_changed:
            marks = [axis.tpdo_count for axis in self.axes]
            owed = [int(due is not None and mark < due) for mark, due in zip(marks, self._late_reply_at)]
        with self._send_lock:
            for axis in self.axes:
                self._network.send_message(axis.rpdo_cob_id, axis.rpdo_data(self._override))
                axis.sent_target_counts = axis.target_counts
            self._network.send_message(SYNC_COB_ID, b"")
        sent_s = time.monotonic()
        self.timing.sent(sent_s, ready_in_time)
        self.count += 1
        if meanwhile is not None:
            meanwhile()
        answer_at = [mark + debt + 1 for mark, debt in zip(marks, owed)]     # tpdo_count once this SYNC's came
        with self._feedback_changed:
            if self.first_reply_timeout_s > self.reply_timeout_s and self._any_reply_last_cycle:
                self._feedback_changed.wait_for(
                    lambda: any(axis.tpdo_count >= due for axis, due in zip(self.axes, answer_at)),
                    timeout=self.first_reply_timeout_s)
            self._feedback_changed.wait_for(
                lambda: all(axis.tpdo_count >= due for axis, due in zip(self.axes, answer_at)),
                timeout=self.reply_timeout_s)
            fresh = tuple(axis.tpdo_count >= due for axis, due in zip(self.axes, answer_at))
            received = [axis.tpdo_count - mark for axis, mark in zip(self.axes, marks)]
        if all(fresh):
            self.answer_latency.add(time.monotonic() - sent_s)
        else:
            self.answer_latency.add_unanswered()
        self._any_reply_last_cycle = any(received)
        self._late_reply_at = [mark + 1 if not is_fresh and count == 0 else None
                               for mark, is_fresh, count in zip(marks, fresh, received)]
        return now_s, fresh

    def _following_sync_s(self, now_s: float) -> float:
        """When the SYNC after the one sent at `now_s` is due. On its grid (due + period) when this
        one left less than a period late; a full period after it otherwise (after a pause such as a
        mode change's SDO exchange, or a stall), rather than at once: drives interpolating in cyclic
        synchronous position assume SYNCs at least a period apart, and a burst of catch-up SYNCs
        would step their set-points."""
        if now_s - self.next_sync_s > self.period_s:
            return now_s + self.period_s
        return self.next_sync_s + self.period_s

    def quick_stop_all(self) -> None:
        """Quick stop to every drive now, and in every later cycle (any thread).

        A drive whose frame cannot be sent (bus-off, adapter gone) does not keep the others
        from getting theirs; its failure is kept in ``send_failures``.
        """
        self.override(cia402.QUICK_STOP)

    def override(self, controlword: int) -> None:
        """Send ``controlword`` to every drive now and in every later cycle instead of its own."""
        with self._send_lock:
            self._override = controlword
            if self._network.bus is None:
                return
            for axis in self.axes:
                try:
                    self._network.send_message(axis.rpdo_cob_id, axis.rpdo_data(controlword))
                except can.CanError as error:
                    self.send_failures.append(f"{axis.name}: controlword 0x{controlword:04X} not sent ({error})")
