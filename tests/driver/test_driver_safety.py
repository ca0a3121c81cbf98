"""Safety stops: every cause stops every axis, with its own exit code and one line naming axis and cause.

Each case runs a cyclic synchronous trajectory on a homed testbed and breaks something in the
middle of it. Afterwards every drive must be in QUICK STOP ACTIVE, SWITCH ON DISABLED or FAULT,
the quick stop must have reached every drive before the next SYNC, and the stop callback (the
log flush) must have run once with the stop. The drives run in a process of their own
(driver_rig.py), as they do behind `crest testbed serve`.
"""

import math
import time

import can
import pytest

from crest.driver import SafetyStop, SdoFailure, cia402, emergency_stop
from crest.driver.cia402 import Cia402State
from crest.exit_codes import ExitCode
from driver_rig import STOPPED_STATES, is_sync, make_config, rpdo1, tpdo1
from sim_backend.faults import FaultKind, parse_fault

QUICK_STOP = 0x0002
BREAK_AT_SAMPLE = 50


def there_and_back(testbed, samples=300):
    """Pull 13 out to 3 mm and back in 3 s, at rest at both ends."""
    return [testbed.targets_from_pulls(1.5 * (1.0 - math.cos(2.0 * math.pi * k / (samples - 1))), 0.0, 20.5)
            for k in range(samples)]


def run_until_stopped(rig, break_something) -> SafetyStop:
    """Run the trajectory, call ``break_something()`` at sample 50, return the SafetyStop raised."""
    stops = []
    rig.testbed.on_safety_stop(stops.append)
    counter = iter(range(10_000))

    def on_sample(sample):
        if next(counter) == BREAK_AT_SAMPLE:
            break_something()

    with pytest.raises(SafetyStop) as raised:
        rig.testbed.run_trajectory(there_and_back(rig.testbed), on_sample)
    assert stops == [raised.value]                       # the log flush ran once, with this stop
    assert str(raised.value).count("\n") == 0            # one line
    return raised.value


def quick_stop_start(rig) -> int:
    """Index of the first quick-stop RPDO1; checks every drive got one before the next SYNC."""
    frames = rig.frames()
    nodes = [axis.node_id for axis in rig.config.axes]
    first = next(i for i, f in enumerate(frames)
                 if any((c := rpdo1(f, node)) and c[0] == QUICK_STOP for node in nodes))
    next_sync = next((i for i in range(first, len(frames)) if is_sync(frames[i])), len(frames))
    for node in nodes:
        assert any((c := rpdo1(f, node)) and c[0] == QUICK_STOP for f in frames[first:next_sync]), f"node {node}"
    return first


def syncs_between(rig, begin: int, end: int) -> int:
    return sum(is_sync(f) for f in rig.frames()[begin:end])


def assert_all_stopped(rig) -> None:
    states = rig.drive_states()
    assert set(states.values()) <= STOPPED_STATES, states


def test_emcy_stops_every_axis_within_one_sync(homed):
    stop = run_until_stopped(homed, lambda: homed.inject_fault("tendon3", FaultKind.EMCY))
    assert (stop.exit_code, stop.axis) == (ExitCode.EMCY, "tendon3")
    assert "EMCY 0x2310 (continuous over current)" in str(stop)
    frames = homed.frames()
    emcy = next(i for i, f in enumerate(frames) if f.arbitration_id == 0x83 and bytes(f.data[:2]) == b"\x10\x23")
    assert syncs_between(homed, emcy, quick_stop_start(homed)) <= 1
    assert_all_stopped(homed)
    assert homed.drive_states()["tendon3"] == "FAULT"
    assert {state for name, state in homed.drive_states().items() if name != "tendon3"} == {"SWITCH_ON_DISABLED"}


def test_an_emcy_scheduled_by_fault_spec_stops_the_testbed(make_rig):
    rig = make_rig(faults=[parse_fault("insertion:emcy@1.5")])   # homing ends near 1 s of simulated time
    rig.testbed.boot()
    rig.testbed.home()
    stop = run_until_stopped(rig, lambda: None)
    assert (stop.exit_code, stop.axis) == (ExitCode.EMCY, "insertion")
    quick_stop_start(rig)
    assert_all_stopped(rig)


def test_heartbeat_loss_of_a_drive_stops_every_axis(homed):
    stop = run_until_stopped(homed, lambda: homed.inject_fault("tendon4", FaultKind.HEARTBEAT))
    assert (stop.exit_code, stop.axis) == (ExitCode.HEARTBEAT_LOST, "tendon4")
    assert "no heartbeat for" in str(stop)
    quick_stop_start(homed)
    assert {state for name, state in homed.drive_states().items() if name != "tendon4"} == {"SWITCH_ON_DISABLED"}
    for _ in range(30):                         # the silent drive stops itself: it no longer hears the host
        homed.advance(0.01)
    assert homed.drive_states()["tendon4"] == "FAULT"
    assert_all_stopped(homed)


def test_a_stalled_motor_is_a_following_error(homed):
    stop = run_until_stopped(homed, lambda: homed.inject_fault("tendon1", FaultKind.STALL))
    assert (stop.exit_code, stop.axis) == (ExitCode.FOLLOWING_ERROR, "tendon1")
    assert "following error" in str(stop)
    quick_stop_start(homed)
    assert_all_stopped(homed)


def test_error_frames_stop_every_axis(homed):
    stop = run_until_stopped(homed, lambda: homed.inject_fault("tendon2", FaultKind.ERROR_FRAMES))
    assert (stop.exit_code, stop.axis) == (ExitCode.BUS_ERROR, "bus")
    frames = homed.frames()
    error_frame = next(i for i, f in enumerate(frames) if f.is_error_frame)
    assert syncs_between(homed, error_frame, quick_stop_start(homed)) <= 1
    assert_all_stopped(homed)


def test_a_drive_that_stops_answering_sdo_stops_every_axis(homed):
    homed.inject_fault("tendon3", FaultKind.SDO_TIMEOUT)
    stops = []
    homed.testbed.on_safety_stop(stops.append)
    with pytest.raises(SafetyStop) as stop:
        homed.testbed.move_to(homed.testbed.targets_from_pulls(1.0, 1.0, 21.0))   # writes profiles by SDO
    assert (stop.value.exit_code, stop.value.axis) == (ExitCode.SDO_FAILURE, "tendon3")
    assert f"no answer within {homed.config.master.sdo_timeout_s:g} s" in str(stop.value)
    assert stops == [stop.value]
    quick_stop_start(homed)
    assert_all_stopped(homed)


def test_tension_above_the_limit_stops_every_axis_before_the_next_sync(homed):
    tendon2 = homed.config.axis("tendon2")
    stop = run_until_stopped(homed, lambda: homed.set_load_tension_n("tendon2", 45.0))
    assert (stop.exit_code, stop.axis) == (ExitCode.TENSION_LIMIT, "tendon2")
    assert "tension 45.0 N exceeds max_tension_n 40 N" in str(stop)
    frames = homed.frames()
    over = next(i for i, f in enumerate(frames)
                if (v := tpdo1(f, tendon2.node_id)) and tendon2.tension_n_from_torque_permille(v[2]) > 40.0)
    assert syncs_between(homed, over, quick_stop_start(homed)) == 0
    assert_all_stopped(homed)


def test_tracker_loss_during_a_closed_loop_run_stops_every_axis(homed):
    clock = homed.clock
    last_sample_s = [clock.now_s()]

    def tip_sample_age_s():
        return clock.now_s() - last_sample_s[0]

    def tracker_alive_until_sample_50(sample):
        if not hasattr(tracker_alive_until_sample_50, "count"):
            tracker_alive_until_sample_50.count = 0
        tracker_alive_until_sample_50.count += 1
        if tracker_alive_until_sample_50.count < BREAK_AT_SAMPLE:
            last_sample_s[0] = clock.now_s()

    homed.testbed.watch_tracker(tip_sample_age_s)
    with pytest.raises(SafetyStop) as stop:
        homed.testbed.run_trajectory(there_and_back(homed.testbed), tracker_alive_until_sample_50)
    assert (stop.value.exit_code, stop.value.axis) == (ExitCode.TRACKER_LOST, "tracker")
    age_s = float(str(stop.value).split("no valid tip sample for ")[1].split(" s")[0])
    assert homed.config.tracker.loss_timeout_s <= age_s <= homed.config.tracker.loss_timeout_s + 0.011
    quick_stop_start(homed)
    assert_all_stopped(homed)


def test_reported_tracker_loss_stops_every_axis(homed):
    stop = run_until_stopped(homed, lambda: homed.testbed.report_tracker_loss(0.4))
    assert (stop.exit_code, stop.axis) == (ExitCode.TRACKER_LOST, "tracker")
    assert_all_stopped(homed)


def test_ctrl_c_in_the_control_loop_stops_every_axis(homed):
    def interrupt():
        raise KeyboardInterrupt
    stop = run_until_stopped(homed, interrupt)
    assert (stop.exit_code, stop.axis) == (ExitCode.INTERRUPTED, None)
    assert isinstance(stop.__cause__, KeyboardInterrupt)
    quick_stop_start(homed)
    assert_all_stopped(homed)


@pytest.mark.parametrize("error, exit_code", [(KeyboardInterrupt(), ExitCode.INTERRUPTED),
                                              (ZeroDivisionError("controller blew up"), ExitCode.EXCEPTION)])
def test_an_exception_in_a_with_block_stops_every_axis(homed, error, exit_code):
    with pytest.raises(SafetyStop) as stop:
        with homed.testbed as testbed:
            for targets in there_and_back(testbed)[:BREAK_AT_SAMPLE]:
                testbed.cycle(targets)
            raise error
    assert stop.value.exit_code == exit_code and stop.value.__cause__ is error
    quick_stop_start(homed)
    assert_all_stopped(homed)


def test_emergency_stop_over_a_second_bus_handle_stops_every_axis(homed):
    """emergency_stop() on a second client of the rig's bus (the drives are in their own process),
    as `crest estop` uses it. The command itself, from another process, is tested in tests/cli."""
    homed.testbed.jog_to(homed.testbed.targets_from_pulls(5.0, 0.0, 40.0))
    for _ in range(10):
        homed.testbed.cycle()
    other_bus = homed.open_bus()
    try:
        outcome = emergency_stop(other_bus, homed.config)
    finally:
        other_bus.shutdown()
    assert set(outcome.values()) <= {Cia402State.QUICK_STOP_ACTIVE, Cia402State.SWITCH_ON_DISABLED}
    with pytest.raises(SafetyStop) as stop:
        homed.testbed.cycle()
    assert stop.value.exit_code == ExitCode.ERROR and "left OPERATION ENABLED" in str(stop.value)
    assert_all_stopped(homed)


def test_emergency_stop_tries_every_axis_and_reports_the_one_it_could_not_reach(make_rig):
    rig = make_rig(config=make_config(sdo_timeout_s=1.0))   # tendon3's is expected to expire, no other's
    rig.testbed.boot()
    rig.inject_fault("tendon3", FaultKind.SDO_TIMEOUT)
    other_bus = rig.open_bus()
    try:
        outcome = emergency_stop(other_bus, rig.config)
    finally:
        other_bus.shutdown()
    assert list(outcome) == ["tendon1", "tendon2", "tendon3", "tendon4", "insertion"]
    assert isinstance(outcome.pop("tendon3"), SdoFailure)
    assert set(outcome.values()) <= {Cia402State.QUICK_STOP_ACTIVE, Cia402State.SWITCH_ON_DISABLED}
    with pytest.raises(SafetyStop) as stop:        # closing needs tendon3's SDO server too
        rig.testbed.close()
    assert (stop.value.exit_code, stop.value.axis) == (ExitCode.SDO_FAILURE, "tendon3")


SILENT_AXIS_TIMEOUT_S = 2.0   # one SDO timeout: stopped one after the other, the others would wait this long


def test_a_drive_that_does_not_answer_delays_no_other_axis_quick_stop(make_rig):
    """The quick stops go out at once: with tendon1, the first axis, silent for its whole 2 s SDO
    timeout, every other axis' quick stop is on the bus before that timeout ends and each is stopped."""
    rig = make_rig(config=make_config(sdo_timeout_s=SILENT_AXIS_TIMEOUT_S))   # expected to expire
    rig.testbed.boot()
    rig.inject_fault("tendon1", FaultKind.SDO_TIMEOUT)
    other_bus = rig.open_bus()
    start_s = time.time()
    try:
        outcome = emergency_stop(other_bus, rig.config)
    finally:
        other_bus.shutdown()
    quick_stop = bytes([0x2B, 0x40, 0x60, 0x00, cia402.QUICK_STOP, 0x00])   # SDO download 0x6040:00 = 2
    sent_s = {f.arbitration_id - 0x600: f.timestamp for f in rig.frames()
              if 0x600 < f.arbitration_id < 0x680 and bytes(f.data[:6]) == quick_stop and f.timestamp >= start_s}
    assert isinstance(outcome.pop("tendon1"), SdoFailure)
    for name, state in outcome.items():
        assert state in {Cia402State.QUICK_STOP_ACTIVE, Cia402State.SWITCH_ON_DISABLED}, name
        assert sent_s[rig.config.axis(name).node_id] < start_s + SILENT_AXIS_TIMEOUT_S, name
    with pytest.raises(SafetyStop):        # closing needs tendon1's SDO server too
        rig.testbed.close()


def test_a_dead_host_stops_the_testbed(homed):
    """No shutdown at all: the host's heartbeat and SYNC just end, as when the process is killed."""
    testbed = homed.testbed
    testbed.jog_to(testbed.targets_from_pulls(8.0, 0.0, 60.0))
    for _ in range(10):
        testbed.cycle()
    assert set(homed.drive_states().values()) == {"OPERATION_ENABLED"}
    moving_mm = homed.position_actual_mm("insertion")
    start = len(homed.frames())
    for _ in range(30):                                  # 0.3 s > heartbeat_timeout_s 0.25 s
        homed.advance(0.01)
    assert set(homed.drive_states().values()) == {"FAULT"}
    assert all(0x8130 in homed.active_error_codes(name) for name in homed.drive_names)
    emcys = {f.arbitration_id for f in homed.frames()[start:] if bytes(f.data[:2]) == b"\x30\x81"}
    assert emcys == {0x80 + axis.node_id for axis in homed.config.axes}
    # Someone else's SYNC would drive the motion on: the faulted drives do not move.
    stranger = homed.open_bus()
    try:
        for _ in range(5):
            stranger.send(can.Message(arbitration_id=0x80, data=b"", is_extended_id=False))
        homed.frames()
    finally:
        stranger.shutdown()
    assert homed.position_actual_mm("insertion") == moving_mm
    assert moving_mm < 59.0
    # A host that was only hung, not dead, learns of it from the drives' EMCY 0x8130.
    with pytest.raises(SafetyStop) as stop:
        testbed.cycle()
    assert stop.value.exit_code == ExitCode.HEARTBEAT_LOST and "0x8130" in str(stop.value)


def lose_emcys(drives, name: str) -> None:
    """In the drives' process: the EMCY frames of drive `name` get lost."""
    drives.drive(name)._emcy = lambda code, register: None


def test_a_drive_fault_without_emcy_is_reset_on_a_rising_edge_when_enabling(booted):
    booted.in_drives(lose_emcys, "tendon1")
    booted.inject_fault("tendon1", FaultKind.EMCY)
    booted.testbed.cycle()
    assert booted.testbed.axes["tendon1"].state is Cia402State.FAULT
    booted.testbed.enable()
    words = [c[0] for f in booted.frames() if (c := rpdo1(f, 1))]
    distinct = [w for i, w in enumerate(words) if i == 0 or w != words[i - 1]]
    assert distinct == [0x0000, 0x0080, 0x0006, 0x0007, 0x010F]   # bit 7 low, then high: one rising edge
    assert booted.drive_states()["tendon1"] == "OPERATION_ENABLED"


def test_close_disables_every_axis_and_stops_the_drives_watching_the_host(homed):
    homed.testbed.close()
    assert set(homed.drive_states().values()) == {"SWITCH_ON_DISABLED"}
    for _ in range(40):
        homed.advance(0.01)                              # longer than the heartbeat timeout
    assert set(homed.drive_states().values()) == {"SWITCH_ON_DISABLED"}
    assert set(homed.nmt_states().values()) == {"PRE-OPERATIONAL"}
