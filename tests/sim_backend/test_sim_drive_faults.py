"""Faults and the frames a real drive sends for them: EMCY codes, error register, silence, error frames."""

import struct

import pytest
from canopen.sdo import SdoCommunicationError

from drive_bench import DriveBench, tendon_spec
from sim_backend.drive.cia402_state_machine import DriveState
from sim_backend.drives import SimDriveSet
from sim_backend.faults import FaultKind, parse_fault

PP, CSP = 1, 8


@pytest.fixture
def bench():
    bench = DriveBench([tendon_spec(), tendon_spec("tendon2", 2)])
    yield bench
    bench.close()


def emcys(bench, node_id=1):
    """(error code, error register) of every EMCY frame from a node."""
    return [struct.unpack_from("<HB", bytes(frame.data)) for frame in bench.recorder.with_id(0x80 + node_id)]


def wait_emcy(bench, code, node_id=1):
    bench.recorder.wait_for(lambda frames: any(c == code for c, _ in emcys(bench, node_id)),
                            f"EMCY 0x{code:04X} from node {node_id}")


def test_injected_emcy_is_over_current_with_current_bit_in_the_error_register(bench):
    node = bench.enable("tendon1", CSP)
    bench.drive("tendon1").inject_fault(FaultKind.EMCY)
    wait_emcy(bench, 0x2310)
    frame = bench.recorder.with_id(0x81)[-1]
    assert len(frame.data) == 8
    assert emcys(bench)[-1] == (0x2310, 0x03)         # generic + current
    assert node.sdo[0x1001].raw == 0x03
    assert node.sdo[0x603F].raw == 0x2310
    assert node.sdo[0x6041].raw & 0x4F == 0x08         # FAULT
    node.emcy.wait(0x2310, timeout=0)                  # canopen's consumer logged it too
    assert [error.code for error in node.emcy.active] == [0x2310]


def test_fault_reset_sends_emcy_error_reset(bench):
    node = bench.enable("tendon1", CSP)
    bench.drive("tendon1").inject_fault(FaultKind.EMCY)
    bench.controlword("tendon1", 0x00)
    bench.controlword("tendon1", 0x80)
    wait_emcy(bench, 0x0000)
    assert emcys(bench)[-1] == (0x0000, 0x00)
    assert node.emcy.active == []
    assert node.sdo[0x1001].raw == 0


def test_stall_becomes_a_following_error_fault_after_the_timeout(bench):
    node = bench.enable("tendon1", PP)
    window = node.sdo[0x6065].raw
    assert window == round(1.0 * bench.drive("tendon1").spec.counts_per_mm)   # 1 mm
    timeout_ms = node.sdo[0x6066].raw
    bench.drive("tendon1").inject_fault(FaultKind.STALL)
    node.sdo[0x607A].raw = 10_000
    bench.controlword("tendon1", 0x1F)
    cycles_over = 0
    following_error_seen = False
    for _ in range(200):
        bench.sync()
        if bench.drive("tendon1").state is DriveState.FAULT:
            break
        error = node.sdo[0x60F4].raw
        if error > window:
            cycles_over += 1
            following_error_seen |= bool(node.sdo[0x6041].raw & 0x2000)
    assert bench.drive("tendon1").state is DriveState.FAULT
    assert following_error_seen                        # statusword bit 13 before the fault
    assert cycles_over * 10 >= timeout_ms              # it waited out 0x6066 first
    wait_emcy(bench, 0x8611)
    assert emcys(bench)[-1] == (0x8611, 0x21)          # generic + device profile
    assert node.sdo[0x6064].raw == 0                   # the jammed motor never moved


def test_lost_master_heartbeat_faults_the_drive_with_emcy_8130(bench):
    node = bench.enable("tendon1", CSP)
    timeout_ms = node.sdo[0x1016][1].raw & 0xFFFF
    assert node.sdo[0x1016][1].raw >> 16 == 127
    bench.master_heartbeat()
    bench.tick(0.0)
    for now_s in (0.05, 0.10, 0.15):
        bench.master_heartbeat()
        bench.tick(now_s)
    bench.tick(0.15 + timeout_ms / 1000.0)             # silent exactly the consumer time: still fine
    assert bench.drive("tendon1").state is DriveState.OPERATION_ENABLED
    bench.tick(0.15 + timeout_ms / 1000.0 + 0.01)
    assert bench.drive("tendon1").state is DriveState.FAULT
    wait_emcy(bench, 0x8130)
    assert emcys(bench)[-1] == (0x8130, 0x11)          # generic + communication
    assert bench.drive("tendon2").state is DriveState.FAULT   # disabled drives watch the master too
    wait_emcy(bench, 0x8130, node_id=2)


def test_heartbeat_consumer_waits_for_the_first_heartbeat(bench):
    bench.enable("tendon1", CSP)
    bench.tick(0.0)
    bench.tick(10.0)                                   # master never started: no monitoring yet
    assert bench.drive("tendon1").state is DriveState.OPERATION_ENABLED


def test_heartbeat_fault_makes_the_drive_silent(bench):
    drive = bench.drive("tendon1")
    bench.enable("tendon1", CSP)
    bench.master_heartbeat()
    bench.tick(0.0)
    drive.inject_fault(FaultKind.HEARTBEAT)
    bench.recorder.clear()
    for now_s in (0.1, 0.2, 0.3, 0.4):
        bench.master_heartbeat(barrier_via="tendon2")
        bench.tick(now_s)
    bench.sync(3, barrier_via="tendon2")
    assert [frame for frame in bench.recorder.frames if frame.arbitration_id & 0x7F == 1] == []
    assert bench.recorder.with_id(0x702)                # the other drive keeps its heartbeat
    assert drive.state is DriveState.FAULT              # it did not hear the master either


def test_sdo_timeout_fault_leaves_pdos_running(bench):
    node = bench.enable("tendon1", CSP)
    bench.drive("tendon1").inject_fault(FaultKind.SDO_TIMEOUT)
    node.sdo.RESPONSE_TIMEOUT = 0.2
    with pytest.raises(SdoCommunicationError):
        node.sdo.upload(0x6041, 0)
    bench.sync(2, barrier_via="tendon2")
    assert len(bench.recorder.with_id(0x181)) == 2


def test_error_frames_until_error_passive_then_emcy_8120_and_warning_bit(bench):
    node = bench.enable("tendon1", CSP)
    bench.drive("tendon1").inject_fault(FaultKind.ERROR_FRAMES)
    for _ in range(40):
        bench.sync()
        if any(code == 0x8120 for code, _ in emcys(bench)):
            break
    errors = len(bench.recorder.error_frames())
    # ISO 11898-1: TEC +8 per error frame, -1 per good frame (not below 0). Per SYNC the drive
    # sends its TPDO, then an error frame: TEC = 8, 15, 22, ... = 7k + 1 after k cycles,
    # error passive at TEC >= 128, i.e. after k = 19 cycles.
    assert errors == 19
    assert emcys(bench)[-1] == (0x8120, 0x11)
    assert node.sdo[0x6041].raw & 0x0080                # warning
    assert node.sdo[0x6041].raw & 0x4F == 0x27 & 0x4F   # still enabled: a warning, not a fault
    bench.sync(3)
    assert len(bench.recorder.error_frames()) == errors  # an error-passive node stops the burst


def test_rpdo_shorter_than_its_mapping_is_emcy_8210(bench):
    bench.enable("tendon1", CSP)
    bench.client.send_message(0x201, bytes([0x0F, 0x00, 0x10]))   # 3 of 6 bytes
    bench.barrier()
    wait_emcy(bench, 0x8210)
    assert bench.nodes["tendon1"].sdo[0x607A].raw == 0


@pytest.mark.parametrize("text, code, register", [("tendon2:emcy@1.0", 0x2310, 0x03)])
def test_scheduled_fault_fires_at_its_time(text, code, register):
    bench = DriveBench([tendon_spec(), tendon_spec("tendon2", 2)], faults=[parse_fault(text)])
    try:
        bench.tick(0.99)
        bench.barrier("tendon2")
        assert emcys(bench, 2) == []
        bench.tick(1.0)
        wait_emcy(bench, code, node_id=2)
        assert emcys(bench, 2) == [(code, register)]
        assert bench.drive("tendon1").active_error_codes == ()
    finally:
        bench.close()


def test_fault_for_an_unknown_axis_is_refused():
    with pytest.raises(ValueError, match="no drive named 'tendon9'"):
        SimDriveSet([tendon_spec()], "unused", faults=[parse_fault("tendon9:stall@1")])


def test_set_point_jump_the_motor_cannot_follow_is_a_following_error(bench):
    node = bench.enable("tendon1", CSP)
    node.sdo[0x607A].raw = round(5.0 * bench.drive("tendon1").spec.counts_per_mm)   # 5 mm in one cycle
    for _ in range(50):
        bench.sync()
        if bench.drive("tendon1").state is DriveState.FAULT:
            break
    wait_emcy(bench, 0x8611)
    assert 0 < bench.drive("tendon1").position_actual_mm < 5.0   # stopped on the way
