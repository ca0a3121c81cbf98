"""Profile position mode: the set-point handshake (CiA 402-2 bits 4, 5, 6, 8 / 10, 12)."""

import pytest

from drive_bench import DriveBench, tendon_spec

DRIVE = "tendon1"
ACK = 0x1000
TARGET_REACHED = 0x0400
PP = 1


@pytest.fixture
def bench():
    bench = DriveBench([tendon_spec()])
    yield bench
    bench.close()


def status(bench) -> int:
    return bench.nodes[DRIVE].sdo[0x6041].raw


def position(bench) -> int:
    return bench.nodes[DRIVE].sdo[0x6064].raw


def run_until_reached(bench, max_cycles=200) -> list[int]:
    """SYNC until the TPDO shows target reached; returns the TPDO positions seen."""
    positions = []
    for _ in range(max_cycles):
        bench.sync()
        tpdo = bench.tpdo1(DRIVE)
        positions.append(tpdo[0x6064])
        if tpdo[0x6041] & TARGET_REACHED:
            return positions
    raise AssertionError("target not reached")


def new_set_point(bench, target: int, controlword: int = 0x1F) -> None:
    bench.nodes[DRIVE].sdo[0x607A].raw = target
    bench.controlword(DRIVE, controlword)


def test_handshake_acknowledge_follows_new_set_point_bit(bench):
    bench.enable(DRIVE, PP)
    assert status(bench) & (ACK | TARGET_REACHED) == TARGET_REACHED  # at rest, nothing to do
    new_set_point(bench, 2000)
    assert status(bench) & ACK
    assert status(bench) & TARGET_REACHED == 0
    bench.controlword(DRIVE, 0x0F)
    assert status(bench) & ACK == 0  # buffer free again
    positions = run_until_reached(bench)
    assert abs(position(bench) - 2000) <= bench.nodes[DRIVE].sdo[0x6067].raw
    rising = positions[:positions.index(max(positions)) + 1]
    assert rising == sorted(rising)
    overshoot_mm = (max(positions) - 2000) / bench.drive(DRIVE).spec.counts_per_mm
    assert overshoot_mm < 0.05  # the profile uses the motor's full acceleration: a small servo overshoot
    assert len(positions) > 5  # a profile, not a jump


def test_actual_position_lags_the_profile_demand(bench):
    bench.enable(DRIVE, PP)
    new_set_point(bench, 10_000)
    bench.controlword(DRIVE, 0x0F)
    bench.sync(5)
    demand = bench.nodes[DRIVE].sdo[0x6062].raw
    actual = position(bench)
    assert 0 < actual < demand
    assert bench.nodes[DRIVE].sdo[0x60F4].raw == demand - actual


def test_profile_velocity_limits_the_demand_and_the_motor_follows_it(bench):
    node = bench.enable(DRIVE, PP)
    velocity_counts_s = 5000
    node.sdo[0x6081].raw = velocity_counts_s
    new_set_point(bench, 8000)
    bench.controlword(DRIVE, 0x0F)
    demands = []
    while not node.sdo[0x6041].raw & TARGET_REACHED:
        bench.sync()
        demands.append(node.sdo[0x6062].raw)
        assert len(demands) < 300
    steps = [b - a for a, b in zip(demands, demands[1:])]
    assert max(steps) <= velocity_counts_s * 0.01 + 1
    assert steps.count(50) > len(steps) // 2       # cruising at the profile velocity
    assert abs(node.sdo[0x606C].raw) < velocity_counts_s / 10   # settling when the target is reached


def test_buffered_set_point_runs_after_the_current_one(bench):
    bench.enable(DRIVE, PP)
    new_set_point(bench, 3000)
    bench.controlword(DRIVE, 0x0F)
    bench.sync(3)
    new_set_point(bench, 1000)                # bit 5 clear: queued behind 3000
    bench.controlword(DRIVE, 0x0F)
    assert status(bench) & ACK                # buffer full: acknowledge stays
    new_set_point(bench, 9999)                # a third set-point is not taken
    bench.controlword(DRIVE, 0x0F)
    positions = []
    for _ in range(300):
        bench.sync()
        positions.append(position(bench))
        if status(bench) & TARGET_REACHED and positions[-1] < 2000:
            break
    assert max(positions) >= 3000 - 20        # first target was reached
    assert max(positions) < 3100
    assert abs(positions[-1] - 1000) <= 20
    assert status(bench) & ACK == 0


def test_change_set_immediately_replaces_the_running_target(bench):
    bench.enable(DRIVE, PP)
    new_set_point(bench, 10_000)
    bench.controlword(DRIVE, 0x0F)
    bench.sync(10)
    new_set_point(bench, 1000, controlword=0x3F)   # bits 4 and 5
    bench.controlword(DRIVE, 0x2F)
    positions = run_until_reached(bench)
    assert max(positions) < 10_000 // 2
    assert abs(position(bench) - 1000) <= 20


def test_relative_set_point_adds_to_the_previous_target(bench):
    bench.enable(DRIVE, PP)
    new_set_point(bench, 2000)
    bench.controlword(DRIVE, 0x0F)
    run_until_reached(bench)
    new_set_point(bench, -500, controlword=0x5F)   # bits 4 and 6
    bench.controlword(DRIVE, 0x4F)
    run_until_reached(bench)
    assert abs(position(bench) - 1500) <= 20


def test_halt_stops_and_resumes(bench):
    bench.enable(DRIVE, PP)
    new_set_point(bench, 10_000)
    bench.controlword(DRIVE, 0x0F)
    bench.sync(10)
    bench.controlword(DRIVE, 0x10F)               # halt
    held = run_until_reached(bench)[-1]
    bench.sync(3)
    assert abs(position(bench) - held) <= bench.nodes[DRIVE].sdo[0x6067].raw
    assert held < 10_000
    assert status(bench) & TARGET_REACHED         # halted and at rest
    bench.controlword(DRIVE, 0x0F)                # release: the target is still valid
    run_until_reached(bench)
    assert abs(position(bench) - 10_000) <= 20


@pytest.mark.parametrize("sync_period_us", [20000, 40000, 100000])
def test_a_long_sync_period_reaches_the_target_without_the_servo_oscillating(bench, sync_period_us):
    """The drive's own position loop runs every 10 ms whatever the SYNC period (0x1006): a slow
    SYNC changes how often the master sees the axis, not how the motor settles."""
    bench.nodes[DRIVE].sdo[0x1006].raw = sync_period_us
    bench.enable(DRIVE, PP)
    new_set_point(bench, 2000)
    bench.controlword(DRIVE, 0x0F)
    positions = run_until_reached(bench, max_cycles=round(2.0e6 / sync_period_us))
    assert abs(position(bench) - 2000) <= bench.nodes[DRIVE].sdo[0x6067].raw
    overshoot_mm = (max(positions) - 2000) / bench.drive(DRIVE).spec.counts_per_mm
    assert overshoot_mm < 0.05
