"""The tip feed in simulated time: a frame late in wall time is not tracker loss; a lost link is."""
import numpy as np

from crest.experiment.tip_feed import TipFeed
from crest.tracker import TipSample, TrackerState

PERIOD_S = 0.025


class LateTracker:
    """Publishes each frame only after ``late_waits`` waits have timed out (a busy host)."""

    def __init__(self, late_waits: int, state: TrackerState = TrackerState.TRACKING,
                 reconnects_while_waited_for: bool = False):
        self.late_waits = late_waits
        self.state = state
        self.reconnects_while_waited_for = reconnects_while_waited_for
        self.frame = 0
        self.timeouts = 0
        self.state_waits = 0
        self._waits = 0

    def wait_state(self, state: TrackerState, timeout_s: float) -> bool:
        self.state_waits += 1
        if self.reconnects_while_waited_for:
            self.state = TrackerState.TRACKING
        return self.state is state

    def fresh_sample(self, timeout_s: float) -> TipSample:
        self._waits += 1
        if self.state is not TrackerState.TRACKING or self._waits <= self.late_waits:
            self.timeouts += 1
            raise TimeoutError("no new sample")
        self._waits = 0
        self.frame += 1
        return TipSample(t_s=0.0, tip_mm=np.array([1.0, 2.0, 3.0]), frame=self.frame, status=0x31)


def test_a_frame_late_in_wall_time_still_arrives_while_the_link_is_up():
    tracker = LateTracker(late_waits=3)
    feed = TipFeed(tracker, sample_period_s=PERIOD_S)
    measurement = feed.poll(0.0)
    assert measurement is not None and tracker.timeouts == 3
    np.testing.assert_allclose(measurement.tip_mm, [1.0, 2.0, 3.0])
    assert feed.age_s() == 0.0


def test_a_lost_link_costs_one_wait_for_reconnection_then_none_and_the_age_grows_in_loop_time():
    tracker = LateTracker(late_waits=0, state=TrackerState.RECONNECTING)
    feed = TipFeed(tracker, sample_period_s=PERIOD_S)
    assert feed.age_s() == float("inf")                 # not polled yet
    assert feed.poll(0.0) is None and tracker.state_waits == 1
    assert feed.age_s() == 0.0                          # no tip yet: the age counts from the first poll
    tracker.state = TrackerState.TRACKING
    assert feed.poll(PERIOD_S) is not None
    tracker.state = TrackerState.RECONNECTING
    for cycle in range(2, 12):
        assert feed.poll(cycle * PERIOD_S) is None
    assert abs(feed.age_s() - 10 * PERIOD_S) < 1e-9
    assert tracker.state_waits == 2 and tracker.timeouts == 0    # one wait per loss, no wait per poll


def test_a_link_back_within_the_grace_gives_the_frame_in_the_same_cycle():
    tracker = LateTracker(late_waits=0, state=TrackerState.RECONNECTING, reconnects_while_waited_for=True)
    feed = TipFeed(tracker, sample_period_s=PERIOD_S)
    measurement = feed.poll(0.0)
    assert measurement is not None and measurement.time_s == 0.0 and tracker.state_waits == 1


class PromptTracker:
    """Answers every request at once with a new frame."""

    state = TrackerState.TRACKING

    def __init__(self):
        self.frame = 0

    def fresh_sample(self, timeout_s: float) -> TipSample:
        self.frame += 1
        return TipSample(t_s=0.0, tip_mm=np.array([1.0, 2.0, 3.0]), frame=self.frame, status=0x31)


def test_in_simulated_time_a_40_hz_tracker_gives_40_tips_per_second_at_a_100_hz_loop():
    tracker = PromptTracker()
    feed = TipFeed(tracker, sample_period_s=PERIOD_S)
    cycle_s = 0.01
    tips = [feed.poll(cycle * cycle_s) is not None for cycle in range(100)]
    assert sum(tips) == 40 and feed.frames == 40 and tracker.frame == 40     # one request per tracker period
    assert not any(a and b for a, b in zip(tips, tips[1:]))      # frames 25 ms apart never fill two 10 ms rows


class FrameSequence:
    """latest() gives the frames of a real-time driver as a 100 Hz loop sees them."""

    state = TrackerState.TRACKING

    def __init__(self, frames):
        self.frames = iter(frames)

    def latest(self) -> TipSample | None:
        frame, tip = next(self.frames)
        return None if frame is None else TipSample(t_s=0.0, tip_mm=tip, frame=frame, status=0x31)


def test_in_real_time_a_tip_is_given_once_per_frame_even_when_two_frames_hold_the_same_tip():
    tip = np.array([1.0, 2.0, 3.0])
    sequence = [(None, None), (1, tip), (1, tip), (2, tip), (2, tip), (2, tip), (3, None), (3, None), (4, tip)]
    feed = TipFeed(FrameSequence(sequence))
    got = [feed.poll(cycle * 0.01) is not None for cycle in range(len(sequence))]
    assert got == [False, True, False, True, False, False, False, False, True]
    assert feed.frames == 4
