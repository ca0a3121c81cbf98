"""The CiA 402 state table, checked against canopen's own p402 tables as an independent reference."""

import pytest
from canopen.profiles.p402 import State402

from sim_backend.drive.cia402_state_machine import (
    STATUSWORD_MASKS, Cia402StateMachine, Command, DriveState, decode_command, state_from_statusword)

NAMES = {state: state.name.replace("_", " ") for state in DriveState}
BY_NAME = {name: state for state, name in NAMES.items()}


def machine_in(state: DriveState) -> Cia402StateMachine:
    machine = Cia402StateMachine()
    machine.state = state
    return machine


@pytest.mark.parametrize("state", list(DriveState))
def test_statusword_bits_of_each_state_match_canopen_masks(state):
    mask, value = State402.SW_MASK[NAMES[state]]
    assert state.statusword_bits & mask == value
    assert state_from_statusword(state.statusword_bits) is state
    assert STATUSWORD_MASKS[state] == (mask, value)


def test_voltage_enabled_bit_is_set_exactly_while_the_power_stage_may_be_on():
    powered = {state for state in DriveState if state.statusword_bits & 0x10}
    assert powered == {DriveState.READY_TO_SWITCH_ON, DriveState.SWITCHED_ON, DriveState.OPERATION_ENABLED,
                       DriveState.QUICK_STOP_ACTIVE, DriveState.FAULT_REACTION_ACTIVE}


COMMANDED = [(source, target, controlword) for (source, target), controlword in State402.TRANSITIONTABLE.items()
             if source in BY_NAME and target in BY_NAME and source not in ("NOT READY TO SWITCH ON",
                                                                         "FAULT REACTION ACTIVE", "FAULT")]


@pytest.mark.parametrize("source, target, controlword", COMMANDED)
def test_every_commanded_transition_of_canopens_table(source, target, controlword):
    machine = machine_in(BY_NAME[source])
    taken = machine.on_controlword(controlword, quick_stop_option=6)
    assert machine.state is BY_NAME[target]
    assert len(taken) == 1


@pytest.mark.parametrize("controlword, command", [
    (0x0006, Command.SHUTDOWN), (0x000E, Command.SHUTDOWN), (0x0007, Command.SWITCH_ON),
    (0x000F, Command.ENABLE_OPERATION), (0x0000, Command.DISABLE_VOLTAGE), (0x000D, Command.DISABLE_VOLTAGE),
    (0x0002, Command.QUICK_STOP), (0x000B, Command.QUICK_STOP), (0x0080, None), (0x008F, None)])
def test_controlword_decoding(controlword, command):
    assert decode_command(controlword) is command


@pytest.mark.parametrize("source, controlword, numbers, target", [
    (DriveState.SWITCH_ON_DISABLED, 0x06, (2,), DriveState.READY_TO_SWITCH_ON),
    (DriveState.READY_TO_SWITCH_ON, 0x07, (3,), DriveState.SWITCHED_ON),
    (DriveState.READY_TO_SWITCH_ON, 0x0F, (3, 4), DriveState.OPERATION_ENABLED),
    (DriveState.SWITCHED_ON, 0x0F, (4,), DriveState.OPERATION_ENABLED),
    (DriveState.OPERATION_ENABLED, 0x07, (5,), DriveState.SWITCHED_ON),
    (DriveState.SWITCHED_ON, 0x06, (6,), DriveState.READY_TO_SWITCH_ON),
    (DriveState.READY_TO_SWITCH_ON, 0x00, (7,), DriveState.SWITCH_ON_DISABLED),
    (DriveState.READY_TO_SWITCH_ON, 0x02, (7,), DriveState.SWITCH_ON_DISABLED),
    (DriveState.OPERATION_ENABLED, 0x06, (8,), DriveState.READY_TO_SWITCH_ON),
    (DriveState.OPERATION_ENABLED, 0x00, (9,), DriveState.SWITCH_ON_DISABLED),
    (DriveState.SWITCHED_ON, 0x00, (10,), DriveState.SWITCH_ON_DISABLED),
    (DriveState.SWITCHED_ON, 0x02, (10,), DriveState.SWITCH_ON_DISABLED),
    (DriveState.OPERATION_ENABLED, 0x02, (11,), DriveState.QUICK_STOP_ACTIVE),
    (DriveState.QUICK_STOP_ACTIVE, 0x00, (12,), DriveState.SWITCH_ON_DISABLED),
])
def test_transition_numbers(source, controlword, numbers, target):
    machine = machine_in(source)
    assert machine.on_controlword(controlword, quick_stop_option=2) == numbers
    assert machine.state is target


@pytest.mark.parametrize("source, controlword", [
    (DriveState.SWITCH_ON_DISABLED, 0x07), (DriveState.SWITCH_ON_DISABLED, 0x0F),
    (DriveState.SWITCHED_ON, 0x07), (DriveState.QUICK_STOP_ACTIVE, 0x06), (DriveState.QUICK_STOP_ACTIVE, 0x07),
    (DriveState.FAULT, 0x06), (DriveState.FAULT, 0x0F), (DriveState.FAULT_REACTION_ACTIVE, 0x80)])
def test_commands_not_in_the_table_are_ignored(source, controlword):
    machine = machine_in(source)
    assert machine.on_controlword(controlword, quick_stop_option=2) == ()
    assert machine.state is source


@pytest.mark.parametrize("option, allowed", [(0, False), (2, False), (4, False), (5, True), (6, True), (8, True)])
def test_transition_16_only_for_quick_stop_options_that_hold(option, allowed):
    machine = machine_in(DriveState.QUICK_STOP_ACTIVE)
    taken = machine.on_controlword(0x0F, quick_stop_option=option)
    assert (taken == (16,)) is allowed
    assert machine.state is (DriveState.OPERATION_ENABLED if allowed else DriveState.QUICK_STOP_ACTIVE)


def test_fault_and_fault_reset_on_the_rising_edge_of_bit_7_only():
    machine = Cia402StateMachine()
    assert machine.power_up() == (0, 1)
    machine.on_controlword(0x80, quick_stop_option=2)  # bit 7 already high before the fault
    assert machine.on_fault() == (13,)
    assert machine.state is DriveState.FAULT_REACTION_ACTIVE
    assert machine.on_fault() == ()
    assert machine.on_fault_reaction_done() == (14,)
    assert machine.on_controlword(0x80, quick_stop_option=2) == ()  # still high: no edge
    assert machine.state is DriveState.FAULT
    assert machine.on_controlword(0x00, quick_stop_option=2) == ()
    assert machine.on_controlword(0x80, quick_stop_option=2) == (15,)
    assert machine.state is DriveState.SWITCH_ON_DISABLED


def test_automatic_quick_stop_end_is_transition_12():
    machine = machine_in(DriveState.QUICK_STOP_ACTIVE)
    assert machine.on_quick_stop_done() == (12,)
    assert machine.state is DriveState.SWITCH_ON_DISABLED
    assert machine.on_quick_stop_done() == ()
