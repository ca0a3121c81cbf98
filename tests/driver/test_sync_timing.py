"""The master's own timing of its SYNCs (crest.driver.sync_timing): rate, jitter and missed cycles
from the send times alone, and each missed cycle by where its time went."""
import math

import pytest

from crest.driver.sync_timing import SyncTiming


def test_a_late_sync_is_one_missed_cycle_and_the_longest_period():
    timing = SyncTiming(0.002)
    sent_s = [k * 0.002 for k in range(100)]
    sent_s[50] += 0.0011                      # 1.55 periods after the 49th: missed; the 51st comes early
    for t in sent_s:
        timing.sent(t)
    summary = timing.summary()
    assert summary["syncs"] == 100 and summary["periods"] == 99 and summary["missed_cycles"] == 1
    assert summary["span_s"] == pytest.approx(0.198)
    assert summary["longest_period_ms"] == pytest.approx(3.1)
    assert summary["achieved_rate_hz"] == pytest.approx(500.0)
    assert summary["jitter_p50_ms"] <= 0.01 and 1.09 <= summary["jitter_p99_ms"] <= 1.11


def test_a_period_of_one_and_a_half_is_not_missed_and_reset_forgets():
    timing = SyncTiming(0.002)
    for t in (0.0, 0.003, 0.005):
        timing.sent(t)
    assert timing.summary()["missed_cycles"] == 0
    timing.reset()
    summary = timing.summary()
    assert summary["syncs"] == 0 and summary["periods"] == 0 and summary["span_s"] == 0.0
    assert math.isnan(summary["achieved_rate_hz"])


def test_a_missed_cycle_whose_cycle_was_ready_in_time_woke_late_and_one_that_was_not_overran():
    """Ready in time: the cycle waited for the due time and its thread ran again too late. Not ready:
    the cycle before it ran past the due time. Only missed cycles are counted either way."""
    timing = SyncTiming(0.002)
    for t, ready_in_time in ((0.0, True), (0.002, True), (0.0055, True), (0.0075, False), (0.011, False),
                             (0.013, True)):
        timing.sent(t, ready_in_time)
    summary = timing.summary()
    assert summary["missed_cycles"] == 2                      # 0.0035 and 0.0035 s periods
    assert summary["missed_woke_late"] == 1 and summary["missed_overran"] == 1
