"""The tip feed in simulated time: a frame late in wall time is not tracker loss; a lost link is."""
import numpy as np

from crest.experiment.tip_feed import TipFeed
from crest.tracker import TipSample, TrackerState

PERIOD_S = 0.025


class LateTracker:
    """Publishes each frame only after ``late_waits`` waits have timed out (a busy host)."""

    def __init__(self, late_waits: int, state: TrackerState = TrackerState.TRACKING):
        self.late_waits = late_waits
        self.state = state
        self.frame = 0
        self.timeouts = 0
        self._waits = 0

    def wait_next(self, timeout_s: float) -> TipSample:
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
    assert measurement is not None and tracker.timeouts == 6
    np.testing.assert_allclose(measurement.tip_mm, [1.0, 2.0, 3.0])
    assert feed.age_s() == 0.0


def test_a_lost_link_gives_no_sample_at_once_and_the_age_grows_in_loop_time():
    tracker = LateTracker(late_waits=0, state=TrackerState.RECONNECTING)
    feed = TipFeed(tracker, sample_period_s=PERIOD_S)
    assert feed.age_s() == float("inf")                 # not polled yet
    assert feed.poll(0.0) is None and tracker.timeouts == 1
    assert feed.age_s() == 0.0                          # no tip yet: the age counts from the first poll
    tracker.state = TrackerState.TRACKING
    assert feed.poll(PERIOD_S) is not None
    tracker.state = TrackerState.RECONNECTING
    for cycle in range(2, 12):
        assert feed.poll(cycle * PERIOD_S) is None
    assert abs(feed.age_s() - 10 * PERIOD_S) < 1e-9
