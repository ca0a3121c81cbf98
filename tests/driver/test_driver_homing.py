"""Homing (mode 6): every axis referenced with its own method, then the tendons pretensioned."""

from dataclasses import replace

import pytest

from crest.driver import Cia402State, OperationMode, SafetyStop
from crest.exit_codes import ExitCode
from driver_rig import INSERTION_START_MM, drive_specs, make_config, sdo_downloads


def test_homing_references_every_axis_and_pretensions_the_tendons(homed):
    testbed, config = homed.testbed, homed.config
    insertion = config.insertion_axis
    # Method 17: the carriage ran down onto its switch (1 mm below where it started) and the
    # drive now reports the switch as home_position_mm, the same frame as the mechanism.
    reported_mm = testbed.positions().insertion_mm
    physical_mm = homed.position_actual_mm("insertion")
    assert reported_mm == pytest.approx(insertion.home_position_mm, abs=0.05)
    assert reported_mm == pytest.approx(physical_mm, abs=1.0 / insertion.counts_per_mm)
    assert physical_mm < INSERTION_START_MM - 0.9
    # Method 37 on the tendons: current position is zero; then both tendons of each pair are
    # pulled to the pretension (pulls 0, 0).
    pretension_mm = config.coordination.pretension_mm
    assert testbed.commanded().tendon_mm == pytest.approx((pretension_mm,) * 4, abs=1e-3)
    assert testbed.commanded().pulls_mm == pytest.approx((0.0, 0.0), abs=1e-9)
    for name, axis in testbed.axes.items():
        assert axis.state is Cia402State.OPERATION_ENABLED and axis.mode is OperationMode.PROFILE_POSITION, name
        modes = [value for index, _, value in sdo_downloads(homed.frames(), axis.config.node_id) if index == 0x6060]
        assert modes == [1, 6, 1], name   # boot, homing, back to profile position


def test_a_homing_error_stops_the_testbed_naming_the_axis(make_rig):
    config = make_config()
    specs = [replace(spec, negative_limit_switch_mm=None) if spec.name == "insertion" else spec
             for spec in drive_specs(config)]
    rig = make_rig(config=config, specs=specs)
    rig.testbed.boot()
    with pytest.raises(SafetyStop) as stop:
        rig.testbed.home()
    assert stop.value.axis == "insertion" and stop.value.exit_code == ExitCode.ERROR
    assert "homing method 17 reported a homing error" in str(stop.value)
    assert set(rig.drive_states().values()) == {"SWITCH_ON_DISABLED"}
