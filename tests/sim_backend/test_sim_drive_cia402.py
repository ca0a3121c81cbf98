"""The drive's CiA 402 state machine on the wire: controlword by SDO, statusword by SDO and TPDO."""

import pytest
from canopen.profiles.p402 import State402

from drive_bench import DriveBench, tendon_spec
from sim_backend.drive.cia402_state_machine import DriveState
from sim_backend.faults import FaultKind

DRIVE = "tendon1"


@pytest.fixture
def bench():
    bench = DriveBench([tendon_spec()])
    yield bench
    bench.close()


def shown_state(statusword: int) -> str:
    for name, (mask, value) in State402.SW_MASK.items():
        if statusword & mask == value:
            return name
    raise AssertionError(f"statusword 0x{statusword:04X} shows no state")


def test_after_boot_the_drive_waits_in_switch_on_disabled_with_remote_set(bench):
    statusword = bench.nodes[DRIVE].sdo[0x6041].raw
    assert shown_state(statusword) == "SWITCH ON DISABLED"
    assert statusword & 0x0200  # remote: the controlword is obeyed
    assert statusword & 0x0008 == 0


PATH = [  # (controlword, state shown afterwards, exact statusword)
    (0x06, "READY TO SWITCH ON", 0x0231),      # 2
    (0x07, "SWITCHED ON", 0x0233),             # 3
    (0x0F, "OPERATION ENABLED", 0x0237),       # 4
    (0x07, "SWITCHED ON", 0x0233),             # 5
    (0x06, "READY TO SWITCH ON", 0x0231),      # 6
    (0x00, "SWITCH ON DISABLED", 0x0240),      # 7
    (0x06, "READY TO SWITCH ON", 0x0231),      # 2
    (0x0F, "OPERATION ENABLED", 0x0237),       # 3 + 4
    (0x06, "READY TO SWITCH ON", 0x0231),      # 8
    (0x0F, "OPERATION ENABLED", 0x0237),
    (0x00, "SWITCH ON DISABLED", 0x0240),      # 9
    (0x06, "READY TO SWITCH ON", 0x0231),
    (0x07, "SWITCHED ON", 0x0233),
    (0x02, "SWITCH ON DISABLED", 0x0240),      # 10 by quick stop
    (0x06, "READY TO SWITCH ON", 0x0231),
    (0x02, "SWITCH ON DISABLED", 0x0240),      # 7 by quick stop
]


def test_standard_transitions_and_statusword_patterns(bench):
    for controlword, state, statusword in PATH:
        assert bench.controlword(DRIVE, controlword) == statusword, f"after 0x{controlword:02X}"
        assert shown_state(statusword) == state
        assert bench.drive(DRIVE).state.name.replace("_", " ") == state


def test_quick_stop_that_holds_allows_transition_16_and_12(bench):
    node = bench.nodes[DRIVE]
    node.sdo[0x605A].raw = 6
    for controlword in (0x06, 0x0F):
        bench.controlword(DRIVE, controlword)
    statusword = bench.controlword(DRIVE, 0x02)                          # 11
    assert shown_state(statusword) == "QUICK STOP ACTIVE"
    assert statusword & 0x0020 == 0                                      # quick stop bit is active low
    assert shown_state(bench.controlword(DRIVE, 0x0F)) == "OPERATION ENABLED"   # 16
    bench.controlword(DRIVE, 0x02)
    assert shown_state(bench.controlword(DRIVE, 0x00)) == "SWITCH ON DISABLED"  # 12 by disable voltage


def test_quick_stop_option_2_ends_in_switch_on_disabled_after_the_ramp(bench):
    node = bench.nodes[DRIVE]
    bench.operational(DRIVE)
    node.sdo[0x6060].raw = 1
    node.sdo[0x607A].raw = 12_000
    for controlword in (0x06, 0x0F, 0x1F, 0x0F):
        bench.controlword(DRIVE, controlword)
    bench.sync(20)
    assert bench.drive(DRIVE).statusword & 0x0400 == 0                    # still moving
    statusword = bench.controlword(DRIVE, 0x02)
    assert shown_state(statusword) == "QUICK STOP ACTIVE"
    stopped_after = 0
    while bench.drive(DRIVE).state is DriveState.QUICK_STOP_ACTIVE:
        bench.sync()
        stopped_after += 1
        assert stopped_after < 50
    assert stopped_after > 1                                              # a ramp, not an instant stop
    assert shown_state(node.sdo[0x6041].raw) == "SWITCH ON DISABLED"       # 12, automatic


def test_fault_then_reset_only_on_a_rising_edge_of_bit_7(bench):
    node = bench.nodes[DRIVE]
    bench.controlword(DRIVE, 0x80)
    bench.drive(DRIVE).inject_fault(FaultKind.EMCY)                       # 13 + 14
    statusword = node.sdo[0x6041].raw
    assert shown_state(statusword) == "FAULT"
    assert statusword == 0x0208
    assert shown_state(bench.controlword(DRIVE, 0x80)) == "FAULT"          # bit 7 was already high
    assert shown_state(bench.controlword(DRIVE, 0x0F)) == "FAULT"          # no command leaves FAULT
    assert shown_state(bench.controlword(DRIVE, 0x80)) == "SWITCH ON DISABLED"   # 15
    assert node.sdo[0x603F].raw == 0
    assert node.sdo[0x1001].raw == 0


def test_base_node_402_client_drives_the_state_machine_by_pdo(bench):
    node = bench.operational(DRIVE)
    node.setup_402_state_machine(read_pdos=False)
    node.tpdo_values[0x6041] = node.sdo[0x6041].raw
    node.controlword = State402.CW_SHUTDOWN
    node.controlword = State402.CW_OPERATION_ENABLED
    bench.sync()
    assert node.state == "OPERATION ENABLED"
    node.controlword = State402.CW_DISABLE_VOLTAGE
    bench.sync()
    assert node.state == "SWITCH ON DISABLED"
