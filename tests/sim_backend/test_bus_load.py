"""Bus load: worst-case frame bits and per-SYNC-cycle load at the bitrate."""

import can
import pytest

from sim_backend.bus_load import BusLoadMeter, frame_bits, message_bits


@pytest.mark.parametrize("data_bytes, bits", [(0, 55), (1, 65), (2, 75), (4, 95), (6, 115), (8, 135)])
def test_standard_frame_worst_case_bits(data_bytes, bits):
    # 47 + 8n + floor((34 + 8n - 1) / 4): the classic 135 bits for 8 bytes
    assert frame_bits(data_bytes) == bits


def test_extended_frame_and_special_frames():
    assert frame_bits(8, extended_id=True) == 67 + 64 + (54 + 64 - 1) // 4 == 160
    assert message_bits(can.Message(arbitration_id=0x701, is_extended_id=False, is_remote_frame=True, dlc=1)) == 55
    assert message_bits(can.Message(is_error_frame=True)) == 23


def test_frame_with_nine_bytes_is_refused():
    with pytest.raises(ValueError, match="0..8 data bytes"):
        frame_bits(9)


def sync():
    return can.Message(arbitration_id=0x80, data=b"", is_extended_id=False)


def frame(cob_id, size):
    return can.Message(arbitration_id=cob_id, data=bytes(size), is_extended_id=False)


def test_cycle_load_of_the_testbed_frame_set():
    """Five drives, each: RPDO1 (6 bytes) before SYNC, TPDO1 (8 bytes) after it."""
    meter = BusLoadMeter(bitrate_bit_s=1_000_000, sync_period_s=0.01)
    meter.on_message_received(frame(0x181, 8))          # before the first SYNC: not counted
    for _ in range(3):
        meter.on_message_received(sync())
        for node_id in range(1, 6):
            meter.on_message_received(frame(0x180 + node_id, 8))
        for node_id in range(1, 6):
            meter.on_message_received(frame(0x200 + node_id, 6))
    report = meter.report()
    bits = 55 + 5 * 135 + 5 * 115                         # 1305 bits per 10 ms cycle
    assert report.cycles == 3
    assert report.mean_load == pytest.approx(bits / 10_000)
    assert report.max_load == pytest.approx(0.1305)
    assert report.overloaded == ()
    assert "3 cycles" in str(report)


def test_cycle_that_does_not_fit_is_reported():
    meter = BusLoadMeter(bitrate_bit_s=125_000, sync_period_s=0.001)   # 125 bits per cycle
    meter.on_message_received(sync())
    meter.on_message_received(sync())
    meter.on_message_received(frame(0x181, 8))
    meter.on_message_received(sync())
    report = meter.report()
    assert report.cycles == 3
    assert [cycle.cycle for cycle in report.overloaded] == [2]
    assert report.overloaded[0].bits == 55 + 135
    assert report.overloaded[0].load == pytest.approx(190 / 125)
    assert "would not fit" in str(report)


def test_a_meter_on_a_handle_of_its_own_measures_the_drives_and_the_host_traffic():
    """As `crest bench` measures the full stack: a third handle on the virtual bus sees every frame."""
    from drive_bench import DriveBench, tendon_spec
    bench = DriveBench([tendon_spec()])
    meter = BusLoadMeter(1_000_000, 0.01)
    monitor = can.Bus(interface="virtual", channel=bench.channel)
    notifier = can.Notifier(monitor, [meter], timeout=0.05)
    try:
        bench.enable("tendon1", 8)
        bench.sync(6)
        # each cycle: SYNC (55) + TPDO1 (135) + SDO request and response of the barrier (2 x 135)
        expected_bits = 55 + 135 + 2 * 135
        bench.recorder.wait_for(lambda frames: meter.report().cycles >= 5, "five metered cycles")
        assert meter.report().max_load == pytest.approx(expected_bits / 10_000)
    finally:
        notifier.stop()
        monitor.shutdown()
        bench.close()
