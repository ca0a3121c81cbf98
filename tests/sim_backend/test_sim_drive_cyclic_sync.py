"""Cyclic synchronous position: set-points latched on SYNC, TPDO1 contents, torque actual."""

import pytest

from drive_bench import DriveBench, tendon_spec

DRIVE = "tendon1"
CSP = 8


@pytest.fixture
def bench():
    bench = DriveBench([tendon_spec()])
    yield bench
    bench.close()


def send_rpdo1(node, controlword: int, target: int) -> None:
    rpdo = node.rpdo[1]
    rpdo["Controlword"].raw = controlword
    rpdo["Target position"].raw = target
    rpdo.transmit()


def test_set_point_is_taken_at_the_sync_not_when_it_arrives(bench):
    node = bench.enable(DRIVE, CSP)
    send_rpdo1(node, 0x0F, 800)
    bench.barrier()
    assert node.sdo[0x607A].raw == 800          # RPDO1 (type 255) is written at once ...
    assert node.sdo[0x6062].raw == 0            # ... but the demand waits for the SYNC
    bench.sync()
    assert node.sdo[0x6062].raw == 800
    assert node.sdo[0x6041].raw & 0x1000        # CSP: drive follows the command value


def test_actual_follows_a_set_point_ramp_with_a_lag_and_settles(bench):
    node = bench.enable(DRIVE, CSP)
    step_counts = 100                           # 10 000 counts/s = 7.7 mm/s
    reported = []
    for k in range(1, 41):
        send_rpdo1(node, 0x0F, k * step_counts)
        bench.sync()
        reported.append(bench.tpdo1(DRIVE)[0x6064])
    # TPDO at SYNC k shows the motor after k-1 cycles, following set-point k-1
    lag = [(k - 1) * step_counts - position for k, position in enumerate(reported, 1)]
    assert lag[0] == 0
    assert lag[1] > step_counts / 2             # the jump to 10 000 counts/s exceeds the motor's acceleration
    assert max(lag) < 2 * step_counts
    assert all(abs(counts) <= 2 for counts in lag[20:])   # velocity feed-forward: no steady lag
    assert reported == sorted(reported)
    bench.sync(20)
    assert abs(node.sdo[0x6064].raw - 40 * step_counts) <= 2


def test_synchronous_rpdo_is_applied_at_the_next_sync(bench):
    node = bench.enable(DRIVE, CSP)
    node.rpdo[1].trans_type = 1
    node.rpdo[1].save()
    assert node.sdo[0x1400][2].raw == 1
    send_rpdo1(node, 0x0F, 500)
    bench.barrier()
    assert node.sdo[0x607A].raw == 0
    bench.sync()
    assert node.sdo[0x607A].raw == 500
    assert node.sdo[0x6062].raw == 500


def test_tpdo1_carries_statusword_position_and_torque_on_every_sync(bench):
    node = bench.enable(DRIVE, CSP)
    drive = bench.drive(DRIVE)
    tension_n = 123.4
    drive.set_load_tension_n(tension_n)
    send_rpdo1(node, 0x0F, 1000)
    bench.sync(30)
    received = bench.recorder.with_id(0x181)
    assert len(received) == 30
    assert all(len(frame.data) == 8 for frame in received)
    tpdo = bench.tpdo1(DRIVE)
    assert tpdo[0x6041] & 0x6F == 0x27
    # torque at the motor = T r / gear = 123.4 N * 5 mm / 10 = 61.7 mNm = 61.7 per mille of 1000 mNm
    assert tpdo[0x6077] == 62
    assert node.sdo[0x6077].raw == 62
    assert tpdo[0x6064] == node.sdo[0x6064].raw  # at rest: the sample equals the present value
    assert abs(tpdo[0x6064] - 1000) <= 2
    assert drive.position_actual_mm == pytest.approx(node.sdo[0x6064].raw / drive.spec.counts_per_mm, abs=1e-3)


def test_no_tpdo_in_pre_operational(bench):
    bench.sync()
    assert bench.recorder.with_id(0x181) == []


def test_tpdo_remapped_by_the_client_is_sent_with_the_new_layout(bench):
    node = bench.nodes[DRIVE]
    node.tpdo.read()
    tpdo2 = node.tpdo[2]
    tpdo2.clear()
    tpdo2.add_variable(0x6041)
    tpdo2.add_variable(0x6062)
    tpdo2.trans_type = 2
    tpdo2.enabled = True
    tpdo2.save()
    assert node.sdo[0x1A01][0].raw == 2
    assert node.sdo[0x1A01][2].raw == 0x60620020
    node.nmt.send_command(0x01)
    bench.sync(4)
    frames = bench.recorder.with_id(0x281)
    assert len(frames) == 2                     # every second SYNC
    assert len(frames[0].data) == 6
    assert tpdo2["Statusword"].raw & 0x4F == 0x40
    assert tpdo2["Position demand value"].raw == node.sdo[0x6062].raw


@pytest.mark.parametrize("objects, code", [
    ([0x6041, 0x606C, 0x6062], 0x06040042),     # 80 bits > 64
    ([0x6065], 0x06040041),                     # following error window is not PDO-mappable
])
def test_invalid_tpdo_mapping_is_refused_with_the_cia_301_abort_code(bench, objects, code):
    from canopen.sdo import SdoAbortedError
    node = bench.nodes[DRIVE]
    node.tpdo.read()
    tpdo2 = node.tpdo[2]
    tpdo2.clear()
    for index in objects:
        tpdo2.add_variable(index)
    tpdo2.enabled = True
    with pytest.raises(SdoAbortedError) as refused:
        tpdo2.save()
    assert refused.value.code == code


def test_mapping_of_a_valid_pdo_cannot_be_changed(bench):
    from canopen.sdo import SdoAbortedError
    node = bench.nodes[DRIVE]
    with pytest.raises(SdoAbortedError) as refused:
        node.sdo[0x1A00][0].raw = 0             # TPDO1 is valid (COB-ID bit 31 clear)
    assert refused.value.code == 0x08000022


def test_sync_listener_couples_a_plant_cycle_by_cycle(bench):
    """A trivial plant: tension proportional to tendon travel, 10 N/mm."""
    drive = bench.drive(DRIVE)
    node = bench.enable(DRIVE, CSP)
    steps = []

    def plant_step(can_id, data, timestamp):
        steps.append(can_id)
        drive.set_load_tension_n(10.0 * drive.position_actual_mm)

    bench.drive_set.add_sync_listener(plant_step)
    for k in range(1, 41):                      # 2 mm in 0.2 s, then hold
        send_rpdo1(node, 0x0F, round(min(k * 0.1, 2.0) * drive.spec.counts_per_mm))
        bench.sync()
    assert steps == [0x80] * 40
    # 2 mm -> 20 N -> 20 N * 5 mm / 10 = 10 mNm = 10 per mille
    assert bench.tpdo1(DRIVE)[0x6077] == 10
