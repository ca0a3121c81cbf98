"""Cyclic synchronous position (mode 8): one set-point per SYNC, through RPDO1, checked on the host."""

import math

import pytest

from crest.driver import AxisTargets, MotionRefused
from driver_rig import is_sync, rpdo1


def bend_there_and_back(testbed, samples=200, pull_mm=2.0, insertion_mm=20.5):
    """Both pulls out and back, at rest at both ends: d(k) = A (1 - cos(2 pi n k / N)) / 2.

    At T = 10 ms, N = 200, A = 2 mm: pull 13 (n = 1) peaks at A pi / (N T) = 3.1 mm/s and
    2 A pi^2 / (N T)^2 = 9.9 mm/s^2; pull 24 (n = 2) at twice and four times that.
    """
    def bump(k, turns):
        return pull_mm * (1.0 - math.cos(2.0 * math.pi * turns * k / (samples - 1))) / 2.0
    return [testbed.targets_from_pulls(bump(k, 1), bump(k, 2), insertion_mm) for k in range(samples)]


def test_a_trajectory_is_followed_one_sync_behind(homed):
    trajectory = bend_there_and_back(homed.testbed)
    cycles = homed.testbed.run_trajectory(trajectory)
    assert len(cycles) == len(trajectory)
    assert {homed.object_value(name, 0x6061) for name in homed.drive_names} == {8}
    # The drives sample the position at the SYNC that latches the next set-point: sample k shows
    # where set-point k-1 took the axis.
    lags = [abs(now.position_mm[i] - before.target_mm[i])
            for before, now in zip(cycles, cycles[1:]) for i in range(5)]
    assert max(lags) < 0.01
    assert cycles[-1].target_mm == pytest.approx(trajectory[-1].values(), abs=1e-3)
    assert all(cycle.limited == () and all(cycle.fresh) for cycle in cycles)


def test_every_sync_is_preceded_by_one_rpdo1_per_drive_with_its_set_point(homed):
    start = len(homed.frames())
    trajectory = bend_there_and_back(homed.testbed, samples=100)
    cycles = homed.testbed.run_trajectory(trajectory)
    frames = homed.frames()[start:]
    sync_indices = [i for i, frame in enumerate(frames) if is_sync(frame)]
    last = len(cycles)
    for k, (begin, end) in enumerate(list(zip(sync_indices, sync_indices[1:]))[-last + 1:], start=1):
        for name, axis in homed.testbed.axes.items():
            commands = [c for f in frames[begin + 1:end + 1] if (c := rpdo1(f, axis.config.node_id))]
            assert len(commands) == 1, (k, name)
            controlword, target_counts = commands[0]
            assert controlword == 0x000F                                             # enabled, halt released
            assert target_counts == axis.config.mm_to_counts(cycles[k].target_mm[list(homed.testbed.axes).index(name)])


def test_a_trajectory_too_fast_for_an_axis_is_refused_before_anything_moves(homed):
    syncs = sum(is_sync(f) for f in homed.frames())
    jump = [homed.testbed.targets_from_pulls(0.0, 0.0, 20.5), homed.testbed.targets_from_pulls(0.5, 0.0, 20.5)]
    with pytest.raises(MotionRefused) as error:
        homed.testbed.run_trajectory(jump)
    assert error.value.axis == "tendon1"
    assert "sample 1: velocity 50.00 mm/s exceeds max_velocity_mm_s 20" in str(error.value)
    assert sum(is_sync(f) for f in homed.frames()) == syncs


def test_streamed_set_points_are_clamped_into_the_limits_and_said_so(homed):
    testbed, tendon1 = homed.testbed, homed.config.axis("tendon1")
    start = testbed.commanded()
    step = AxisTargets((start.tendon_mm[0] + 3.0,) + start.tendon_mm[1:], start.insertion_mm)
    first = testbed.cycle(step)
    assert len(first.limited) == 1 and first.limited[0].startswith("tendon1: set-point")
    period_s = homed.config.sync.period_s
    commanded = [start.tendon_mm[0], first.target_mm[0]]
    for _ in range(150):
        commanded.append(testbed.cycle(step).target_mm[0])
    velocities = [(b - a) / period_s for a, b in zip(commanded, commanded[1:])]
    accelerations = [(b - a) / period_s for a, b in zip(velocities, velocities[1:])]
    count_mm = 1.0 / tendon1.counts_per_mm   # set-points go out in whole counts
    assert max(abs(v) for v in velocities) <= tendon1.max_velocity_mm_s + count_mm / period_s
    assert max(abs(a) for a in accelerations) <= tendon1.max_acceleration_mm_s2 + 2 * count_mm / period_s ** 2
    assert max(abs(v) for v in velocities) > 0.9 * tendon1.max_velocity_mm_s
    assert commanded[-1] == pytest.approx(step.tendon_mm[0], abs=1.0 / tendon1.counts_per_mm)
    beyond = AxisTargets((15.0,) + start.tendon_mm[1:], start.insertion_mm)
    for _ in range(200):
        sample = testbed.cycle(beyond)
    assert sample.target_mm[0] == pytest.approx(tendon1.soft_max_mm, abs=1.0 / tendon1.counts_per_mm)
    assert "clamped to soft limit 12 mm" in sample.limited[0]
