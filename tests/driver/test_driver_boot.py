"""Boot sequence against the simulated drives: NMT, identity, configuration, heartbeat, SYNC."""

import os
from dataclasses import replace

import numpy as np
import pytest

from crest.driver import BootError, IdentityMismatch, ReadBackMismatch
from crest.exit_codes import ExitCode
from crest.testbed_service.served_bus import ServedBus
from driver_rig import drive_specs, is_sync, make_config, sdo_downloads


def process_id(drives) -> int:
    """In the drives' process: its id."""
    return os.getpid()


def test_the_master_meets_the_drives_in_another_process_over_the_served_bus(booted):
    assert booted.in_drives(process_id) != os.getpid()
    assert isinstance(booted.bus, ServedBus) and booted.bus_url.startswith("ws://127.0.0.1:")


def test_boot_resets_each_node_before_talking_to_it_and_ends_operational(booted):
    frames = booted.frames()
    for axis in booted.config.axes:
        resets = [i for i, f in enumerate(frames) if f.arbitration_id == 0x000 and bytes(f.data) == bytes([0x81, axis.node_id])]
        boot_ups = [i for i, f in enumerate(frames) if f.arbitration_id == 0x700 + axis.node_id and bytes(f.data) == b"\x00"]
        first_sdo = next(i for i, f in enumerate(frames) if f.arbitration_id == 0x600 + axis.node_id)
        assert len(resets) == 1 and resets[0] < first_sdo, axis.name
        assert any(resets[0] < i < first_sdo for i in boot_ups), f"{axis.name}: SDO before its boot-up"
        start = next(i for i, f in enumerate(frames) if f.arbitration_id == 0x000 and bytes(f.data) == bytes([0x01, axis.node_id]))
        assert start > max(i for i, f in enumerate(frames) if f.arbitration_id == 0x600 + axis.node_id)
        assert booted.nmt_states()[axis.name] == "OPERATIONAL"
        assert booted.drive_states()[axis.name] == "SWITCH_ON_DISABLED"


def test_boot_writes_the_axis_parameters_in_counts(booted):
    config = booted.config
    for axis in config.axes:
        def value(index, subindex=0, name=axis.name):
            return booted.object_value(name, index, subindex)
        per_mm = axis.counts_per_mm
        assert value(0x1006) == 10_000                                   # 10 ms SYNC period in us
        assert value(0x6081) == round(axis.max_velocity_mm_s * per_mm)
        assert value(0x6083) == value(0x6084) == round(axis.max_acceleration_mm_s2 * per_mm)
        assert (value(0x607D, 1), value(0x607D, 2)) == (round(axis.soft_min_mm * per_mm),
                                                                  round(axis.soft_max_mm * per_mm))
        assert value(0x6065) == round(axis.following_error_window_mm * per_mm)
        assert value(0x605A) == 2
        assert value(0x6098) == axis.homing_method
        assert value(0x1017) == 50
        assert value(0x1016, 1) == 127 << 16 | 250                       # watch node 127, 250 ms
        assert value(0x6061) == 1                                        # profile position


def test_after_a_pause_the_sync_resumes_a_full_period_apart_not_in_a_burst(booted):
    period_s = booted.config.sync.period_s
    on_grid = [booted.testbed.cycle().t_s for _ in range(3)]
    booted.advance(5 * period_s)                         # a pause: the host sends nothing
    resumed = [booted.testbed.cycle().t_s for _ in range(3)]
    assert np.diff(on_grid) == pytest.approx([period_s] * 2)
    assert np.diff(resumed) == pytest.approx([period_s] * 2)   # before: the second SYNC at once


def test_identity_is_reported_from_0x1018(make_rig):
    report = make_rig().testbed.boot()
    assert {name: identity.serial for name, identity in report.identities.items()} == {
        "tendon1": 1, "tendon2": 2, "tendon3": 3, "tendon4": 4, "insertion": 5}
    assert {identity.vendor_id for identity in report.identities.values()} == {0x43525354}


def test_host_heartbeat_and_sync_run_at_their_configured_periods(booted):
    syncs_before = sum(is_sync(f) for f in booted.frames())
    heartbeats_before = sum(f.arbitration_id == 0x77F for f in booted.frames())
    for _ in range(30):                                  # 0.3 s of 10 ms cycles
        booted.testbed.cycle()
    frames = booted.frames()
    assert sum(is_sync(f) for f in frames) == syncs_before + 30
    heartbeats = [f for f in frames if f.arbitration_id == 0x77F][heartbeats_before:]
    assert len(heartbeats) == 6                          # every 50 ms
    assert {bytes(f.data) for f in heartbeats} == {b"\x05"}   # OPERATIONAL


def test_a_missing_drive_fails_the_boot_naming_it(make_rig):
    config = make_config(boot_timeout_s=1.0)   # shorter than configured, so the test ends soon; wall time
    rig = make_rig(config=config, specs=[spec for spec in drive_specs(config) if spec.name != "insertion"])
    with pytest.raises(BootError) as error:
        rig.testbed.boot()
    assert error.value.axis == "insertion"
    assert "boot-up" in str(error.value) and "0x705" in str(error.value)


def test_a_drive_of_another_vendor_is_refused(make_rig, tmp_path):
    config = make_config()
    eds = tmp_path / "other_vendor.eds"
    eds.write_text(config.axis("tendon2").eds_path.read_text().replace("0x43525354", "0x00000123"))
    specs = [replace(spec, eds_path=eds) if spec.name == "tendon2" else spec for spec in drive_specs(config)]
    rig = make_rig(config=config, specs=specs)
    with pytest.raises(IdentityMismatch) as error:
        rig.testbed.boot()
    assert error.value.axis == "tendon2" and error.value.exit_code == ExitCode.CONFIG
    assert "0x1018:1 vendor id is 0x00000123" in str(error.value)


def test_a_motor_rated_torque_other_than_configured_is_refused(make_rig):
    config = make_config()
    specs = [replace(spec, rated_torque_mnm=1000.0) if spec.name == "tendon4" else spec for spec in drive_specs(config)]
    rig = make_rig(config=config, specs=specs)
    with pytest.raises(ReadBackMismatch) as error:
        rig.testbed.boot()
    assert error.value.axis == "tendon4" and "0x6076" in str(error.value) and "1000 mNm" in str(error.value)


def test_consumer_heartbeat_is_the_last_sdo_write_of_every_drive(booted):
    for axis in booted.config.axes:
        writes = sdo_downloads(booted.frames(), axis.node_id)
        boot_writes = [w for w in writes if w[0] != 0x1016 or w[2] != 0]
        assert boot_writes[-1] == (0x1016, 1, 0x007F00FA), axis.name


def test_holding_keeps_the_drives_alive_past_their_heartbeat_timeout(booted):
    booted.testbed.enable()
    sample = booted.testbed.hold(1.0)                      # four heartbeat timeouts
    assert sample.t_s >= 1.0
    assert set(booted.drive_states().values()) == {"OPERATION_ENABLED"}
    assert booted.testbed.safety_stop is None


def test_status_reads_state_position_and_fault_of_every_axis(make_rig):
    from sim_backend.faults import FaultKind
    rig = make_rig()
    rig.inject_fault("tendon2", FaultKind.EMCY)     # before any host: nothing to stop
    rig.testbed.connect()
    for _ in range(6):
        rig.advance(0.01)                                 # one drive heartbeat period
    rows = {row.axis: row for row in rig.testbed.status()}
    assert rows["tendon2"].state.name == "FAULT" and rows["tendon2"].fault == "0x2310 (continuous over current)"
    assert rows["tendon1"].state.name == "SWITCH_ON_DISABLED" and rows["tendon1"].fault == ""
    assert {row.nmt_state for row in rows.values()} == {"PRE-OPERATIONAL"}
    assert rows["insertion"].position_mm == pytest.approx(21.0, abs=1e-3)   # where the carriage stands
    assert rows["insertion"].node_id == 5 and rows["insertion"].following_error_mm == 0.0
