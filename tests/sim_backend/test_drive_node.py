"""The drive's object dictionary (sim_backend.drive.drive_node): what is read is what was last
written, by the drive itself (`store`) or from the bus (an SDO download or an RPDO, `set_data`),
though the node remembers lookups and decoded values between SYNCs."""
import pytest

from sim_backend.drive.drive_node import DriveNode
from tests.sim_backend.drive_bench import EDS_PATH

STATUSWORD, TARGET_POSITION, MODE_DISPLAY = 0x6041, 0x607A, 0x6061


@pytest.fixture
def node():
    written = []
    node = DriveNode(1, str(EDS_PATH), on_written=lambda index, sub: written.append((index, sub)),
                     on_reset=lambda command: None, send=lambda cob_id, data: None)
    node.written = written
    return node


def test_a_value_stored_by_the_drive_reads_back_and_as_the_bytes_on_the_bus(node):
    node.store(STATUSWORD, 0, 0x0237)
    assert node.value(STATUSWORD) == 0x0237
    node.store(STATUSWORD, 0, 0x0237)                    # the same again
    node.store(STATUSWORD, 0, 0x0631)
    assert node.value(STATUSWORD) == 0x0631
    assert node.get_data(STATUSWORD, 0) == bytes([0x31, 0x06])


def test_a_write_from_the_bus_replaces_what_the_drive_stored_and_is_reported(node):
    node.store(TARGET_POSITION, 0, 1000)
    assert node.value(TARGET_POSITION) == 1000
    node.set_data(TARGET_POSITION, 0, (-25).to_bytes(4, "little", signed=True))
    assert node.value(TARGET_POSITION) == -25 and node.written == [(TARGET_POSITION, 0)]
    node.store(TARGET_POSITION, 0, 1000)                 # the value stored before the write: stored again
    assert node.value(TARGET_POSITION) == 1000
    assert node.get_data(TARGET_POSITION, 0) == (1000).to_bytes(4, "little", signed=True)


def test_an_object_never_written_reads_its_eds_default_and_a_missing_one_is_a_key_error(node):
    assert node.value(MODE_DISPLAY) == node.od_variable(MODE_DISPLAY).default
    with pytest.raises(KeyError, match="0x1018:09"):
        node.od_variable(0x1018, 9)             # the identity object has subindexes 0-4
