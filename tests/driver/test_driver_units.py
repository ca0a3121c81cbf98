"""The driver's pure parts: CiA 402 words, PDO packing, set-point geometry, limits, stop causes."""

import math

import canopen
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from crest.driver import AxisTargets, Cia402State, MotionRefused
from crest.driver.cia402 import command_toward_enabled, state_from_statusword
from crest.driver.motion_limits import SetPointLimiter, check_trajectory
from crest.driver.pdo_layout import PdoLayout
from crest.driver.stop_causes import emcy_cause
from crest.driver.synchronized_move import synchronized_move
from crest.exit_codes import ExitCode
from driver_rig import make_config
from sim_backend.drive.cia402_state_machine import Cia402StateMachine, DriveState


@pytest.mark.parametrize("statusword, state", [
    (0x0000, Cia402State.NOT_READY_TO_SWITCH_ON), (0x0250, Cia402State.SWITCH_ON_DISABLED),
    (0x0231, Cia402State.READY_TO_SWITCH_ON), (0x0233, Cia402State.SWITCHED_ON),
    (0x1637, Cia402State.OPERATION_ENABLED), (0x0217, Cia402State.QUICK_STOP_ACTIVE),
    (0x021F, Cia402State.FAULT_REACTION_ACTIVE), (0x0218, Cia402State.FAULT), (0x0208, Cia402State.FAULT)])
def test_statusword_decoding_follows_the_cia_402_table(statusword, state):
    assert state_from_statusword(statusword) is state


def test_a_statusword_without_a_state_is_an_error():
    with pytest.raises(ValueError, match="0x0001"):
        state_from_statusword(0x0001)


@pytest.mark.parametrize("start", [DriveState.SWITCH_ON_DISABLED, DriveState.READY_TO_SWITCH_ON,
                                   DriveState.SWITCHED_ON, DriveState.QUICK_STOP_ACTIVE, DriveState.FAULT])
def test_the_command_path_enables_the_independent_state_machine_of_the_simulator(start):
    """Driven by the host's path, sim_backend's own CiA 402 machine reaches OPERATION ENABLED."""
    machine = Cia402StateMachine()
    machine.power_up()
    machine.on_controlword(0x000F, 2)            # previous controlword: bit 7 low
    machine.state = start
    previous = 0x000F
    for _ in range(6):
        state = state_from_statusword(machine.state.statusword_bits)
        command = command_toward_enabled(state, previous)
        if command is None:
            break
        machine.on_controlword(command, 2)
        previous = command
    assert machine.state is DriveState.OPERATION_ENABLED


def test_fault_reset_is_a_rising_edge_of_bit_7():
    assert command_toward_enabled(Cia402State.FAULT, 0x000F) == 0x0000
    assert command_toward_enabled(Cia402State.FAULT, 0x0000) == 0x0080
    assert command_toward_enabled(Cia402State.FAULT, 0x0080) == 0x0000   # held high: low again first
    assert command_toward_enabled(Cia402State.OPERATION_ENABLED, 0x000F) is None


def test_pdo_layout_packs_in_mapping_order_with_eds_types():
    config = make_config()
    axis = config.axis("tendon1")
    od = canopen.import_od(str(axis.eds_path), axis.node_id)
    tpdo = PdoLayout("tendon1", "TPDO1", axis.tpdo1, od)
    data = bytes.fromhex("3706" "feffffff" "38ff")          # 0x0637, -2 counts, -200 per mille
    assert tpdo.unpack(data) == {0x6041: 0x0637, 0x6064: -2, 0x6077: -200}
    rpdo = PdoLayout("tendon1", "RPDO1", axis.rpdo1, od)
    assert rpdo.pack({0x6040: 0x010F, 0x607A: -1}) == bytes.fromhex("0f01" "ffffffff")
    with pytest.raises(ValueError, match="7 data bytes, its mapping needs 8"):
        tpdo.unpack(data[:7])


def test_pairs_pull_against_each_other_around_the_pretension():
    targets = AxisTargets.from_pulls(1.5, -0.5, 40.0, pretension_mm=0.02)
    u1, u2, u3, u4 = targets.tendon_mm
    assert (u1 + u3, u2 + u4) == pytest.approx((0.04, 0.04))
    assert targets.pulls_mm == pytest.approx((1.5, -0.5))
    assert targets.by_axis()["insertion"] == 40.0
    with pytest.raises(ValueError, match="tendon3"):
        AxisTargets((0.0, 0.0, math.nan, 0.0), 30.0)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-20.0, 20.0), min_size=5, max_size=5))
def test_a_synchronized_move_covers_every_distance_in_one_duration_within_the_limits(distances):
    v_max, a_max = [20.0, 20.0, 20.0, 20.0, 10.0], [200.0, 200.0, 200.0, 200.0, 100.0]
    move = synchronized_move(distances, v_max, a_max)
    if move.duration_s == 0.0:
        assert all(abs(d) <= 1e-9 for d in distances)
        return
    for d, v, a, profile in zip(distances, v_max, a_max, move.profiles):
        assert profile.velocity_mm_s <= v * (1 + 1e-9) and profile.acceleration_mm_s2 <= a * (1 + 1e-9)
        # trapezoid: accelerate t_a, cruise, decelerate t_a: distance v (T - t_a)
        assert profile.velocity_mm_s * (move.duration_s - move.acceleration_time_s) == pytest.approx(abs(d), abs=2e-9)
        if profile.velocity_mm_s:
            assert profile.velocity_mm_s / profile.acceleration_mm_s2 == pytest.approx(move.acceleration_time_s)
    assert move.acceleration_time_s <= move.duration_s / 2 + 1e-12
    tight = [max(p.velocity_mm_s / v, p.acceleration_mm_s2 / a) for p, v, a in zip(move.profiles, v_max, a_max)]
    assert max(tight) == pytest.approx(1.0)          # the slowest axis runs at its limit: shortest move


def test_a_feasible_stream_passes_the_limiter_unchanged():
    axis = make_config().axis("tendon1")
    limiter = SetPointLimiter(axis, 0.01, 0.0)
    stream = [2.0 * (1 - math.cos(2 * math.pi * k / 200)) / 2 for k in range(200)]
    assert [limiter.limit(x) for x in stream] == [(x, None) for x in stream]


def test_a_step_is_ramped_and_stops_on_the_set_point():
    axis = make_config().axis("tendon1")
    limiter = SetPointLimiter(axis, 0.01, 0.0)
    out = [limiter.limit(5.0) for _ in range(200)]
    positions = [0.0] + [position for position, _ in out]
    assert out[0][1].startswith("tendon1: set-point 5.000 mm needs 500.0 mm/s")
    velocities = [(b - a) / 0.01 for a, b in zip(positions, positions[1:])]
    assert max(velocities) == pytest.approx(axis.max_velocity_mm_s)
    assert max(abs(b - a) / 0.01 for a, b in zip(velocities, velocities[1:])) <= axis.max_acceleration_mm_s2 + 1e-6
    assert max(positions) <= 5.0 + 1e-9 and positions[-1] == pytest.approx(5.0)


def test_a_trajectory_must_start_and_end_at_rest():
    """Checked as if the first and last samples were held: 0.03 mm per cycle at once is 300 mm/s^2."""
    config = make_config()
    at_rest = AxisTargets((0.0,) * 4, 30.0)
    with pytest.raises(MotionRefused, match="sample 1: acceleration 300.0 mm/s\\^2") as refused:
        check_trajectory(config, [at_rest] + [AxisTargets((0.03 * k,) + (0.0,) * 3, 30.0) for k in range(1, 4)])
    assert refused.value.axis == "tendon1"
    with pytest.raises(MotionRefused, match="after the last sample"):   # 3 mm/s to rest in one cycle
        check_trajectory(config, [at_rest] + [AxisTargets((x,) + (0.0,) * 3, 30.0) for x in (0.01, 0.03, 0.06)])
    check_trajectory(config, [at_rest] * 3 + [AxisTargets((0.005,) + (0.0,) * 3, 30.0)])   # 50 mm/s^2 both ways


@pytest.mark.parametrize("code, exit_code", [(0x2310, ExitCode.EMCY), (0x8611, ExitCode.FOLLOWING_ERROR),
                                             (0x8130, ExitCode.HEARTBEAT_LOST), (0x8120, ExitCode.BUS_ERROR),
                                             (0x4310, ExitCode.EMCY)])
def test_emcy_codes_map_to_their_exit_codes(code, exit_code):
    cause = emcy_cause("tendon2", code)
    assert cause.exit_code == exit_code
    assert cause.line.startswith(f"safety stop ({exit_code.name}): tendon2: EMCY 0x{code:04X} (")
