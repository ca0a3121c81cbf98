"""A TPDO1 carries no SYNC counter: a reply that comes after its cycle gave up on it must not pass
for the next SYNC's answer (crest.driver.sync_cycle). Stub drives deliver TPDO1s when told, so each
test sets the order of SYNCs and replies exactly."""
import threading
import time

from crest.driver.clock import SteppedClock
from crest.driver.sync_cycle import SyncCycle

REPLY_TIMEOUT_S = 0.05


class StubAxis:
    """What SyncCycle reads of a DriveAxis: its RPDO and its TPDO1 count."""

    def __init__(self, name: str, node_id: int, changed: threading.Condition):
        self.name, self.rpdo_cob_id = name, 0x200 + node_id
        self.target_counts = self.sent_target_counts = 0
        self.tpdo_count = 0
        self._changed = changed

    def rpdo_data(self, controlword=None) -> bytes:
        return bytes(6)

    def reply(self) -> None:
        with self._changed:
            self.tpdo_count += 1
            self._changed.notify_all()


class StubNetwork:
    def send_message(self, cob_id: int, data: bytes) -> None:
        pass


class NoHeartbeat:
    def poll(self, now_s: float) -> None:
        pass


def make_cycle(first_reply_timeout_s: float = 0.0):
    changed = threading.Condition()
    axes = [StubAxis("tendon1", 1, changed), StubAxis("tendon2", 2, changed)]
    cycle = SyncCycle(StubNetwork(), SteppedClock(), axes, 0.01, NoHeartbeat(), changed,
                      reply_timeout_s=REPLY_TIMEOUT_S, first_reply_timeout_s=first_reply_timeout_s)
    return cycle, axes


def test_a_reply_in_its_own_cycle_is_fresh():
    cycle, axes = make_cycle()
    _, fresh = cycle.run(meanwhile=lambda: [axis.reply() for axis in axes])
    assert fresh == (True, True)


def test_a_late_reply_is_not_taken_for_the_next_syncs_answer():
    cycle, (late, prompt) = make_cycle()
    _, fresh = cycle.run(meanwhile=prompt.reply)              # tendon1 misses its SYNC
    assert fresh == (False, True)
    _, fresh = cycle.run(meanwhile=lambda: (late.reply(), prompt.reply()))   # only the late answer comes
    assert fresh == (False, True)


def test_after_the_late_reply_the_next_one_answers_the_new_sync():
    cycle, (late, prompt) = make_cycle()
    cycle.run(meanwhile=prompt.reply)
    _, fresh = cycle.run(meanwhile=lambda: (late.reply(), late.reply(), prompt.reply()))
    assert fresh == (True, True)


def test_a_late_reply_that_came_between_cycles_settles_the_debt():
    cycle, (late, prompt) = make_cycle()
    cycle.run(meanwhile=prompt.reply)
    late.reply()                                              # before the next SYNC is sent
    _, fresh = cycle.run(meanwhile=lambda: (late.reply(), prompt.reply()))
    assert fresh == (True, True)


def test_a_reply_that_never_comes_leaves_the_drive_in_step_a_cycle_later_not_behind_for_good():
    cycle, (dropped, prompt) = make_cycle()
    cycle.run(meanwhile=prompt.reply)                         # tendon1's reply is lost
    both = lambda: (dropped.reply(), prompt.reply())          # noqa: E731
    assert cycle.run(meanwhile=both)[1] == (False, True)      # one reply: the old one or this one, unknown
    assert cycle.run(meanwhile=both)[1] == (True, True)
    assert cycle.run(meanwhile=both)[1] == (True, True)


def test_simulated_time_waits_for_a_slow_host_but_not_for_one_silent_drive():
    """With first-reply patience, a SYNC answered 0.3 s late by every drive is fresh; once one drive
    has answered, a silent one gets only the ordinary reply time."""
    cycle, axes = make_cycle(first_reply_timeout_s=5.0)
    timer = threading.Timer(0.3, lambda: [axis.reply() for axis in axes])
    timer.start()
    _, fresh = cycle.run()
    timer.join()
    assert fresh == (True, True)
    started_s = time.monotonic()
    _, fresh = cycle.run(meanwhile=axes[1].reply)
    assert fresh == (False, True) and time.monotonic() - started_s < 2.0


def test_without_that_patience_a_reply_later_than_the_reply_time_is_not_fresh():
    cycle, axes = make_cycle()
    timer = threading.Timer(0.3, lambda: [axis.reply() for axis in axes])
    timer.start()
    _, fresh = cycle.run()
    timer.join()
    assert fresh == (False, False)


def test_after_a_cycle_with_no_reply_at_all_the_next_waits_only_the_ordinary_reply_time():
    """A testbed that is gone is found by the heartbeats within their timeout, not waited for each SYNC."""
    cycle, _ = make_cycle(first_reply_timeout_s=0.5)
    started_s = time.monotonic()
    cycle.run()
    first_s = time.monotonic() - started_s
    started_s = time.monotonic()
    for _ in range(3):
        assert cycle.run()[1] == (False, False)
    assert first_s >= 0.5 and time.monotonic() - started_s < first_s


def test_each_cycle_records_how_long_its_answers_took_or_that_one_did_not_come():
    changed = threading.Condition()
    slow, prompt = StubAxis("tendon1", 1, changed), StubAxis("tendon2", 2, changed)
    patient = SyncCycle(StubNetwork(), SteppedClock(), [slow, prompt], 0.01, NoHeartbeat(), changed,
                        reply_timeout_s=30.0)
    timer = threading.Timer(0.02, slow.reply)
    patient.run(meanwhile=lambda: (timer.start(), prompt.reply()))   # slow answers 20 ms after the SYNC
    timer.join()
    assert patient.answer_latency.answered == 1 and patient.answer_latency.unanswered == 0
    assert 0.02 <= patient.answer_latency.longest_s < 30.0
    cycle, (silent, prompt) = make_cycle()
    cycle.run(meanwhile=prompt.reply)                       # silent does not answer
    assert cycle.answer_latency.answered == 0 and cycle.answer_latency.unanswered == 1
