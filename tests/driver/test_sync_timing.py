"""The master's own timing of its SYNCs (crest.driver.sync_timing): rate, jitter and missed cycles
from the send times alone."""
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
