"""Profile position (mode 1): synchronized point moves, the bit 4 / bit 12 handshake, halt, jogging."""

import pytest

from crest.driver import AxisTargets, MotionRefused
from driver_rig import is_sync, rpdo1, tpdo1


def tpdo_positions_mm(rig, name):
    axis = rig.config.axis(name)
    return [axis.counts_to_mm(values[1]) for f in rig.frames() if (values := tpdo1(f, axis.node_id))]


def test_a_point_move_reaches_every_target_within_the_position_window(homed):
    targets = homed.testbed.targets_from_pulls(3.0, -2.0, 35.0)
    homed.testbed.move_to(targets)
    reached = homed.testbed.positions()
    assert reached.values() == pytest.approx(targets.values(), abs=0.021)  # position window 0.02 mm + 1 count
    assert [homed.position_actual_mm(name) for name in ("tendon1", "insertion")] == pytest.approx(
        [3.0 + homed.config.coordination.pretension_mm, 35.0], abs=0.021)


def test_antagonistic_tendons_keep_the_pretension_all_the_way(homed):
    """The move is a straight line in axis space: u1 + u3 = u2 + u4 = 2 p at every SYNC."""
    testbed = homed.testbed
    start = len(tpdo_positions_mm(homed, "tendon1"))
    testbed.move_to(testbed.targets_from_pulls(4.0, 1.5, 30.0))
    pairs = [(tpdo_positions_mm(homed, a)[start:], tpdo_positions_mm(homed, b)[start:])
             for a, b in (("tendon1", "tendon3"), ("tendon2", "tendon4"))]
    pretension_mm = homed.config.coordination.pretension_mm
    for first, second in pairs:
        assert len(first) > 50
        sums = [x + y for x, y in zip(first, second)]
        assert max(abs(total - 2 * pretension_mm) for total in sums) < 0.005
    moved_13 = [x - pretension_mm for x in pairs[0][0]]
    assert max(moved_13) == pytest.approx(4.0, abs=0.02)


def test_the_slowest_axis_runs_at_its_limit_and_the_others_in_proportion(homed):
    """Insertion 40 mm at 10 mm/s sets the pace; tendon 1 (5 mm) gets 5/40 of that profile speed."""
    start = len(tpdo_positions_mm(homed, "insertion"))
    homed.testbed.move_to(homed.testbed.targets_from_pulls(-5.0, 5.0, 60.0))
    insertion, tendon1 = homed.config.insertion_axis, homed.config.axis("tendon1")
    distance_mm = 60.0 - homed.testbed.axes["insertion"].config.home_position_mm
    profile_counts_s = {name: homed.object_value(name, 0x6081) for name in ("tendon1", "insertion")}
    assert profile_counts_s["insertion"] == round(insertion.max_velocity_mm_s * insertion.counts_per_mm)
    assert tendon1.counts_to_mm(profile_counts_s["tendon1"]) == pytest.approx(
        insertion.max_velocity_mm_s * 5.0 / distance_mm, rel=0.01)
    period_s = homed.config.sync.period_s
    peaks = {}
    for name in ("tendon1", "insertion"):
        positions = tpdo_positions_mm(homed, name)[start:]
        peaks[name] = max(abs(b - a) / period_s for a, b in zip(positions, positions[1:]))
    # The motors follow their profiles; catching up the servo lag may briefly take a few % more.
    assert peaks["insertion"] == pytest.approx(insertion.max_velocity_mm_s, rel=0.05)
    assert peaks["tendon1"] == pytest.approx(peaks["insertion"] * 5.0 / distance_mm, rel=0.05)


def test_set_point_handshake_on_the_wire(homed):
    node = homed.config.axis("tendon1").node_id
    start = len(homed.frames())
    homed.testbed.move_to(homed.testbed.targets_from_pulls(1.0, 0.0, 20.5))
    events = []   # ("rpdo", controlword, target) / ("tpdo", statusword), in bus order
    for frame in homed.frames()[start:]:
        if (command := rpdo1(frame, node)) is not None:
            events.append(("rpdo", command[0], command[1]))
        elif (feedback := tpdo1(frame, node)) is not None:
            events.append(("tpdo", feedback[0]))
    rise = next(i for i, event in enumerate(events) if event[0] == "rpdo" and event[1] & 0x10)
    target_counts = events[rise][2]
    pretension_mm = homed.config.coordination.pretension_mm
    assert target_counts == homed.config.axis("tendon1").mm_to_counts(1.0 + pretension_mm)
    earlier = [event for event in events[:rise] if event[0] == "rpdo"]
    assert earlier[-1][2] == target_counts and not earlier[-1][1] & 0x10   # target sent a cycle before bit 4
    assert not events[rise][1] & 0x0100                                     # halt released with the set-point
    ack = next(i for i, event in enumerate(events) if i > rise and event[0] == "tpdo" and event[1] & 0x1000)
    fall = next(i for i, event in enumerate(events) if i > ack and event[0] == "rpdo" and not event[1] & 0x10)
    released = next(i for i, event in enumerate(events) if i > fall and event[0] == "tpdo")
    assert not events[released][1] & 0x1000
    assert all(event[1] & 0x10 for event in events[rise:fall] if event[0] == "rpdo")  # bit 4 held until acknowledged


def test_halt_is_set_from_enable_until_a_target_is_given(booted):
    node = booted.config.axis("tendon2").node_id
    booted.testbed.enable()
    for _ in range(5):
        booted.testbed.cycle()
    enabled = [command for f in booted.frames() if (command := rpdo1(f, node)) and command[0] & 0x0F == 0x0F]
    assert enabled and all(controlword == 0x010F for controlword, _ in enabled)
    assert booted.position_actual_mm("tendon2") == 0.0                      # nothing moved


def test_a_target_outside_the_soft_limits_is_refused_before_anything_moves(homed):
    syncs = sum(is_sync(f) for f in homed.frames())
    before = homed.testbed.positions()
    with pytest.raises(MotionRefused) as error:
        homed.testbed.move_to(AxisTargets((13.0, 0.0, 0.0, 0.0), 30.0))
    assert error.value.axis == "tendon1" and "soft_limits_mm [-12, 12]" in str(error.value)
    assert sum(is_sync(f) for f in homed.frames()) == syncs
    assert homed.testbed.positions() == before
    homed.testbed.move_to(homed.testbed.targets_from_pulls(0.5, 0.0, 21.0))   # still usable


def test_jogging_replaces_the_target_on_the_way(homed):
    testbed = homed.testbed
    testbed.jog_to(testbed.targets_from_pulls(6.0, 0.0, 20.0), speed_fraction=0.25)
    for _ in range(20):
        testbed.cycle()
    on_the_way_mm = testbed.positions().pulls_mm[0]
    assert 0.2 < on_the_way_mm < 6.0
    testbed.jog_to(testbed.targets_from_pulls(-1.0, 0.0, 20.0), speed_fraction=0.25)
    speeds, last = [], testbed.positions().tendon_mm[0]
    for _ in range(200):
        position = testbed.cycle().tendon_position_mm[0]
        speeds.append(abs(position - last) / homed.config.sync.period_s)
        last = position
    assert testbed.positions().pulls_mm[0] == pytest.approx(-1.0, abs=0.02)
    tendon1 = homed.config.axis("tendon1")
    cap_mm_s = 0.25 * tendon1.max_velocity_mm_s                                      # the jog speed cap
    assert homed.object_value("tendon1", 0x6081) == round(cap_mm_s * tendon1.counts_per_mm)
    assert max(speeds) <= cap_mm_s * 1.05   # the servo catching up its lag after the reversal


def test_a_move_on_a_host_that_sends_its_syncs_late_gets_the_drives_time_not_a_false_timeout(homed):
    """Every SYNC leaves 1.5 periods late (a busy host): the drives, which move one cycle per SYNC, take
    2.5 times as long in the master's time, past the planned time plus its margin; the move still ends
    at its targets rather than in a timeout."""
    period_s = homed.config.sync.period_s
    on_time = homed.clock.wait_until
    homed.clock.wait_until = lambda deadline_s: on_time(deadline_s + 1.5 * period_s)
    start_s = homed.clock.now_s()
    targets = homed.testbed.targets_from_pulls(0.0, 0.0, 60.0)        # insertion 40 mm at 10 mm/s
    homed.testbed.move_to(targets)
    assert homed.clock.now_s() - start_s > 2 * (40.0 / 10.0) + 1.0      # well past the planned time + margin
    assert homed.testbed.positions().values() == pytest.approx(targets.values(), abs=0.021)
