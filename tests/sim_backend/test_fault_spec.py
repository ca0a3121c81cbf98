"""Parsing of ``--fault AXIS:KIND@SECONDS``."""

import itertools

import pytest

from sim_backend.faults import FaultKind, FaultSchedule, FaultSpec, parse_fault


@pytest.mark.parametrize("text, axis, kind, at_s", [
    ("tendon3:emcy@2.0", "tendon3", FaultKind.EMCY, 2.0),
    ("insertion:heartbeat@1", "insertion", FaultKind.HEARTBEAT, 1.0),
    ("tendon1:stall@0", "tendon1", FaultKind.STALL, 0.0),
    ("tendon4:sdo_timeout@0.25", "tendon4", FaultKind.SDO_TIMEOUT, 0.25),
    ("tendon2:error_frames@3e0", "tendon2", FaultKind.ERROR_FRAMES, 3.0),
    ("tracker:disconnect@1.5", "tracker", FaultKind.DISCONNECT, 1.5),
    ("tracker:crc@4", "tracker", FaultKind.CRC, 4.0),
    (" tracker:missing_tool@0.5 ", "tracker", FaultKind.MISSING_TOOL, 0.5),
])
def test_valid_specs(text, axis, kind, at_s):
    fault = parse_fault(text)
    assert fault == FaultSpec(axis, kind, at_s)
    assert fault.targets_tracker is (axis == "tracker")
    assert parse_fault(str(fault)) == fault


@pytest.mark.parametrize("text, message", [
    ("tendon3-emcy@2", "AXIS:KIND@SECONDS"),
    ("tendon3:emcy", "AXIS:KIND@SECONDS"),
    (":emcy@2", "AXIS:KIND@SECONDS"),
    ("tendon3:explode@2", "unknown kind 'explode'"),
    ("tendon3:emcy@soon", "not a number"),
    ("tendon3:emcy@-1", ">= 0"),
    ("tendon3:emcy@nan", ">= 0"),
    ("tracker:stall@1", "the tracker takes kinds crc, disconnect, missing_tool"),
    ("tendon1:crc@1", "use tracker:crc@"),
])
def test_invalid_specs_say_what_is_wrong(text, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(")):
        parse_fault(text)


def test_fault_spec_is_frozen():
    fault = parse_fault("tendon1:stall@1")
    with pytest.raises(AttributeError):
        fault.at_s = 2.0


def test_schedule_hands_out_each_fault_once_in_time_order():
    late, early = parse_fault("tendon1:stall@2"), parse_fault("tracker:crc@1")
    schedule = FaultSchedule([late, early])
    assert schedule.due(0.5) == []
    assert schedule.due(1.0) == [early]
    assert schedule.due(5.0) == [late]
    assert schedule.due(6.0) == []
    assert schedule.pending == ()


def test_a_fault_is_due_on_the_same_step_whether_the_time_is_a_sum_of_steps_or_a_stamps_milliseconds():
    """Inside one process the time is a stepped clock's float sum of 10 ms steps; across the process
    boundary it is a TIME stamp's whole milliseconds. A fault 0.5 s after a clock started at step
    688 is due at step 738 both ways (the float difference of those sums is 0.4999999999...)."""
    summed_s = list(itertools.accumulate([0.01] * 800, initial=0.0))
    stamped_s = [round(t_s * 1000.0) / 1000.0 for t_s in summed_s]

    def due_step(times_s):
        schedule = FaultSchedule([parse_fault("tendon3:emcy@0.5")], held=True)
        schedule.start_clock(times_s[688])
        return next(step for step, t_s in enumerate(times_s) if schedule.due(t_s))

    assert summed_s[738] - summed_s[688] < 0.5
    assert due_step(summed_s) == due_step(stamped_s) == 738
