"""Software position limits (0x607D) and homing (methods 37, 35, 17)."""

import pytest

from drive_bench import DriveBench, insertion_spec, tendon_spec

PP, HM, CSP = 1, 6, 8
INTERNAL_LIMIT = 0x0800
TARGET_REACHED = 0x0400
ATTAINED = 0x1000
HOMING_ERROR = 0x2000


@pytest.fixture
def bench():
    bench = DriveBench([tendon_spec(), insertion_spec()])
    yield bench
    bench.close()


def counts(bench, name, mm):
    return round(mm * bench.drive(name).spec.counts_per_mm)


def test_limits_come_from_the_axis_scaling(bench):
    node = bench.nodes["tendon1"]
    # 4096 counts/rev * 10 / (2 pi 5 mm) = 1303.8 counts/mm; limits +-12 mm
    assert node.sdo[0x607D][1].raw == -15646
    assert node.sdo[0x607D][2].raw == 15646


def test_profile_target_beyond_the_limit_is_clamped_and_flagged(bench):
    node = bench.enable("tendon1", PP)
    node.sdo[0x6081].raw = counts(bench, "tendon1", 20.0)
    node.sdo[0x607A].raw = counts(bench, "tendon1", 30.0)
    bench.controlword("tendon1", 0x1F)
    bench.controlword("tendon1", 0x0F)
    for _ in range(300):
        bench.sync()
        if bench.tpdo1("tendon1")[0x6041] & TARGET_REACHED:
            break
    statusword = node.sdo[0x6041].raw
    assert statusword & INTERNAL_LIMIT
    assert abs(node.sdo[0x6064].raw - node.sdo[0x607D][2].raw) <= node.sdo[0x6067].raw
    node.sdo[0x607A].raw = 0
    bench.controlword("tendon1", 0x1F)
    assert node.sdo[0x6041].raw & INTERNAL_LIMIT == 0  # a set-point inside the limits clears it


def test_cyclic_set_point_below_the_limit_is_clamped_each_cycle(bench):
    node = bench.enable("tendon1", CSP)
    low = node.sdo[0x607D][1].raw
    node.sdo[0x607A].raw = low - 5000
    bench.sync()
    assert node.sdo[0x6062].raw == low
    assert node.sdo[0x6041].raw & INTERNAL_LIMIT
    node.sdo[0x607A].raw = low + 100
    bench.sync()
    assert node.sdo[0x6041].raw & INTERNAL_LIMIT == 0


def test_limits_are_off_when_min_is_not_below_max(bench):
    node = bench.enable("tendon1", CSP)
    node.sdo[0x607D][1].raw = 0
    node.sdo[0x607D][2].raw = 0
    node.sdo[0x607A].raw = 50_000
    bench.sync()
    assert node.sdo[0x6062].raw == 50_000


def test_homing_on_current_position_sets_the_home_offset(bench):
    node = bench.enable("tendon1", PP)
    node.sdo[0x607A].raw = 3000
    bench.controlword("tendon1", 0x1F)
    bench.sync(80)
    motor_mm = bench.drive("tendon1").position_actual_mm
    node.sdo[0x6060].raw = HM
    node.sdo[0x6098].raw = 35
    node.sdo[0x607C].raw = -250
    statusword = bench.controlword("tendon1", 0x0F)
    assert statusword & (ATTAINED | HOMING_ERROR) == 0                    # not started yet
    statusword = bench.controlword("tendon1", 0x1F)
    assert statusword & (ATTAINED | TARGET_REACHED | HOMING_ERROR) == ATTAINED | TARGET_REACHED
    assert node.sdo[0x6064].raw == -250
    assert bench.drive("tendon1").position_actual_mm == motor_mm     # the motor did not move
    node.sdo[0x6060].raw = CSP
    node.sdo[0x607A].raw = -250
    bench.sync(5)
    assert node.sdo[0x6064].raw == -250                               # targets are in the new frame


def test_homing_on_the_negative_limit_switch_finds_the_switch_edge(bench):
    node = bench.enable("insertion", HM)
    drive = bench.drive("insertion")
    assert drive.position_actual_mm == pytest.approx(30.0)
    assert node.sdo[0x6098].raw == 17
    bench.controlword("insertion", 0x1F)
    positions_mm = []
    for _ in range(2000):
        bench.sync(barrier_via="insertion")
        positions_mm.append(drive.position_actual_mm)
        if node.sdo[0x6041].raw & (ATTAINED | HOMING_ERROR):
            break
    statusword = node.sdo[0x6041].raw
    assert statusword & (ATTAINED | TARGET_REACHED | HOMING_ERROR) == ATTAINED | TARGET_REACHED
    assert min(positions_mm) < 20.0                # it ran onto the switch at 20 mm ...
    assert positions_mm[-1] > 20.0                 # ... and came back off it
    # home offset 0x607C = 20 mm: the reported position is now the plant's frame
    assert node.sdo[0x607C].raw == counts(bench, "insertion", 20.0)
    assert node.sdo[0x6064].raw == pytest.approx(drive.position_actual_mm * drive.spec.counts_per_mm, abs=1)


def test_limit_switch_homing_without_a_switch_is_a_homing_error():
    bench = DriveBench([insertion_spec(negative_limit_switch_mm=None)])
    try:
        bench.enable("insertion", HM)
        statusword = bench.controlword("insertion", 0x1F)
        assert statusword & (ATTAINED | HOMING_ERROR) == HOMING_ERROR
    finally:
        bench.close()


def test_halt_interrupts_homing(bench):
    node = bench.enable("insertion", HM)
    bench.controlword("insertion", 0x1F)
    bench.sync(10, barrier_via="insertion")
    assert node.sdo[0x6041].raw & (ATTAINED | HOMING_ERROR | TARGET_REACHED) == 0   # in progress
    bench.controlword("insertion", 0x11F)
    bench.sync(barrier_via="insertion")
    assert node.sdo[0x6041].raw & (ATTAINED | HOMING_ERROR | TARGET_REACHED) == TARGET_REACHED  # interrupted


def test_unsupported_homing_method_is_refused(bench):
    from canopen.sdo import SdoAbortedError
    with pytest.raises(SdoAbortedError) as refused:
        bench.nodes["tendon1"].sdo[0x6098].raw = 1
    assert refused.value.code == 0x06090030
