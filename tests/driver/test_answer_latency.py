"""The histogram of the drives' answer latency (crest.driver.answer_latency): percentiles to a bin,
the longest exact, unanswered cycles apart, fixed memory whatever the run's length."""
import math

import pytest

from crest.driver.answer_latency import AnswerLatency
from crest.driver.wall_time_histogram import BIN_S


def test_percentiles_are_read_to_a_bin_and_the_longest_exactly():
    latency = AnswerLatency()
    for k in range(1, 1001):                        # 0.001 .. 1.000 ms in 1 us steps
        latency.add(k * 1e-6)
    latency.add(0.2)                                # one far tail, past every percentile asked
    latency.add_unanswered()
    summary = latency.summary()
    assert summary["answered"] == 1001 and summary["unanswered"] == 1
    # rank 501 of 1001 is 0.501 ms, rank 991 is 0.991 ms: each read as the upper edge of its bin
    assert 0.501 <= summary["p50_ms"] <= 0.501 + 1e3 * BIN_S
    assert 0.991 <= summary["p99_ms"] <= 0.991 + 1e3 * BIN_S
    assert summary["longest_ms"] == pytest.approx(200.0)


def test_no_answered_cycle_gives_no_percentile():
    latency = AnswerLatency()
    latency.add_unanswered()
    assert math.isnan(latency.percentile_s(50.0)) and latency.summary()["unanswered"] == 1


def test_reset_forgets_everything():
    latency = AnswerLatency()
    latency.add(0.001)
    latency.reset()
    assert latency.summary()["answered"] == 0 and latency.longest_s == 0.0
