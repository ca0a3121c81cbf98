"""Which missed SYNC cycles the machine's stalls explain (crest.bench.missed_cycles): a miss is the
machine's only where the SYNC would have been in time without the stall time inside its period."""
import pytest

from crest.bench.missed_cycles import attribute_missed_cycles, merged

PERIOD_S = 0.002        # 500 Hz


def sync_times(lateness_s: dict[int, float], cycles: int = 100, start_s: float = 1000.0) -> list[float]:
    """SYNCs every period, the i-th of them (and so all after it) `lateness_s[i]` later."""
    times, shift = [], 0.0
    for i in range(cycles):
        shift += lateness_s.get(i, 0.0)
        times.append(start_s + i * PERIOD_S + shift)
    return times


def test_on_time_syncs_miss_nothing_and_jitter_below_half_a_period_is_no_miss():
    result = attribute_missed_cycles(sync_times({10: 0.0009, 50: 0.0004}), PERIOD_S, [])
    assert (result.total, result.in_machine_stalls, result.by_the_stack) == (0, 0, 0)


def test_a_late_sync_inside_a_machine_stall_is_the_machines():
    times = sync_times({20: 0.005})                      # the 20th SYNC 5 ms late
    stall = (times[19] + 0.0005, times[19] + 0.0065)     # the machine stood still 6 ms in that period
    result = attribute_missed_cycles(times, PERIOD_S, [stall])
    assert (result.total, result.in_machine_stalls, result.by_the_stack) == (1, 1, 0)


def test_a_late_sync_with_no_stall_is_the_stacks_and_says_how_late():
    result = attribute_missed_cycles(sync_times({30: 0.003}), PERIOD_S, [])
    assert (result.total, result.by_the_stack) == (1, 1)
    assert result.stack_late_ms == pytest.approx((3.0,))


def test_a_stall_shorter_than_the_lateness_leaves_the_rest_to_the_stack():
    times = sync_times({40: 0.005})
    result = attribute_missed_cycles(times, PERIOD_S, [(times[39] + 0.0002, times[39] + 0.0012)])
    assert (result.in_machine_stalls, result.by_the_stack) == (0, 1)
    assert result.stack_late_ms == pytest.approx((4.0,))     # 5 ms late, 1 ms of it the machine's


def test_a_stall_outside_the_late_period_explains_nothing():
    times = sync_times({60: 0.004})
    result = attribute_missed_cycles(times, PERIOD_S, [(times[70], times[70] + 0.010)])
    assert result.by_the_stack == 1


def test_both_cpus_stalling_together_count_their_common_time_once():
    """Two probes see the same 2 ms pause: 2 ms of the 3.5 ms are explained, not 4 ms."""
    times = sync_times({80: 0.0035})
    pause = (times[79] + 0.0001, times[79] + 0.0021)
    result = attribute_missed_cycles(times, PERIOD_S, [pause, pause])
    assert result.by_the_stack == 1 and result.stack_late_ms == pytest.approx((1.5,))
    assert merged([(3.0, 4.0), (1.0, 2.0), (1.5, 2.5), (4.0, 5.0)]) == [(1.0, 2.5), (3.0, 5.0)]
