"""NMT, SDO server and heartbeat producer of the simulated drive (CiA 301)."""

import pytest

from drive_bench import DriveBench, insertion_spec, tendon_spec

BOOT_UP = bytes([0x00])


@pytest.fixture
def bench():
    bench = DriveBench([tendon_spec(), insertion_spec()])
    yield bench
    bench.close()


def boot_ups(bench, node_id):
    return [frame for frame in bench.recorder.with_id(0x700 + node_id) if bytes(frame.data) == BOOT_UP]


def test_each_drive_sends_its_boot_up_message_on_start(bench):
    bench.recorder.wait_for(lambda frames: boot_ups(bench, 1) and boot_ups(bench, 5), "boot-up of nodes 1 and 5")
    assert len(boot_ups(bench, 1)) == 1
    assert bench.drive("tendon1").nmt_state == "PRE-OPERATIONAL"


@pytest.mark.parametrize("command", [0x81, 0x82])
def test_nmt_reset_sends_boot_up_and_returns_to_pre_operational(bench, command):
    node = bench.nodes["tendon1"]
    bench.barrier()
    node.nmt.send_command(0x01)
    bench.barrier()
    assert bench.drive("tendon1").nmt_state == "OPERATIONAL"
    bench.recorder.clear()
    node.nmt.send_command(command)
    bench.recorder.wait_for(lambda frames: boot_ups(bench, 1), "boot-up after reset")
    bench.barrier("insertion")
    assert bench.drive("tendon1").nmt_state == "PRE-OPERATIONAL"
    assert len(boot_ups(bench, 1)) == 1
    assert boot_ups(bench, 5) == []  # addressed to node 1 only


def test_reset_node_restores_written_objects_but_reset_communication_keeps_application_ones(bench):
    node = bench.nodes["tendon1"]
    node.sdo[0x6081].raw = 1234
    node.sdo[0x1017].raw = 500
    node.nmt.send_command(0x82)  # SDOs below are processed after the reset
    assert node.sdo[0x6081].raw == 1234
    assert node.sdo[0x1017].raw == 50
    node.nmt.send_command(0x81)
    assert node.sdo[0x6081].raw == round(20.0 * bench.drive("tendon1").spec.counts_per_mm)


def test_identity_object_by_sdo(bench):
    node = bench.nodes["insertion"]
    assert node.sdo[0x1000].raw == 0x00020192  # CiA 402 servo drive
    assert node.sdo[0x1018][1].raw == 0x43525354
    assert node.sdo[0x1018][2].raw == 0x00000402
    assert node.sdo[0x1018][3].raw == 0x00010000
    assert node.sdo[0x1018][4].raw == 5
    assert node.sdo[0x1008].raw == "CREST virtual servo"  # segmented upload
    assert node.sdo[0x6502].raw == 0xA1  # PP, HM, CSP


def test_sdo_errors_are_aborts_with_cia_301_codes(bench):
    from canopen.sdo import SdoAbortedError
    node = bench.nodes["tendon1"]
    with pytest.raises(SdoAbortedError) as missing:
        node.sdo.upload(0x2000, 0)
    assert missing.value.code == 0x06020000
    with pytest.raises(SdoAbortedError) as read_only:
        node.sdo.download(0x6041, 0, b"\x00\x00")
    assert read_only.value.code == 0x06010002
    with pytest.raises(SdoAbortedError) as mode:
        node.sdo[0x6060].raw = 3  # profile velocity is not supported (0x6502)
    assert mode.value.code == 0x06090030


def test_heartbeat_producer_runs_on_tick_with_the_nmt_state(bench):
    bench.barrier()
    bench.recorder.clear()
    bench.tick(0.0)
    bench.tick(0.049)
    bench.barrier()
    assert bench.recorder.with_id(0x701) == []
    bench.tick(0.05)
    bench.recorder.wait_for(lambda frames: bench.recorder.with_id(0x701), "heartbeat of node 1")
    assert [bytes(frame.data) for frame in bench.recorder.with_id(0x701)] == [bytes([0x7F])]
    bench.nodes["tendon1"].nmt.send_command(0x02)  # STOPPED
    bench.barrier("insertion")
    bench.tick(0.10)
    bench.recorder.wait_for(lambda frames: len(bench.recorder.with_id(0x701)) == 2, "second heartbeat")
    assert bytes(bench.recorder.with_id(0x701)[1].data) == bytes([0x04])


def test_a_heartbeat_is_due_after_one_period_when_the_time_is_a_stamps_whole_milliseconds(bench):
    """Across the process boundary the drives' time comes in a TIME stamp's whole milliseconds:
    0.06 - 0.01 is 0.04999999999999999 as floats, yet 50 ms have passed."""
    bench.barrier()
    bench.tick(0.01)
    bench.barrier()
    bench.recorder.clear()
    bench.tick(0.06)
    bench.recorder.wait_for(lambda frames: bench.recorder.with_id(0x701), "heartbeat of node 1 at 0.06 s")


def test_stopped_drive_answers_no_sdo_and_sends_no_pdo(bench):
    from canopen.sdo import SdoCommunicationError
    node = bench.nodes["tendon1"]
    node.nmt.send_command(0x02)
    node.sdo.RESPONSE_TIMEOUT = 0.2
    with pytest.raises(SdoCommunicationError):
        node.sdo.upload(0x1000, 0)
    bench.sync(barrier_via="insertion")
    assert bench.recorder.with_id(0x181) == []
