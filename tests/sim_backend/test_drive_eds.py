"""The drive EDS (CiA 306) as both canopen node types read it."""

import canopen
import pytest
from canopen.objectdictionary import datatypes

from drive_bench import EDS_PATH

U8, U16, U32 = datatypes.UNSIGNED8, datatypes.UNSIGNED16, datatypes.UNSIGNED32
I8, I16, I32 = datatypes.INTEGER8, datatypes.INTEGER16, datatypes.INTEGER32


@pytest.fixture(scope="module")
def od():
    return canopen.import_od(str(EDS_PATH), 3)


def entry(od, index, subindex=0):
    obj = od[index]
    return obj if isinstance(obj, canopen.objectdictionary.ODVariable) else obj[subindex]


@pytest.mark.parametrize("index, subindex, data_type, access, mappable", [
    (0x1000, 0, U32, "ro", False), (0x1001, 0, U8, "ro", True), (0x1006, 0, U32, "rw", False),
    (0x1016, 1, U32, "rw", False), (0x1017, 0, U16, "rw", False), (0x1018, 4, U32, "ro", False),
    (0x603F, 0, U16, "ro", True), (0x6040, 0, U16, "rww", True), (0x6041, 0, U16, "ro", True),
    (0x605A, 0, I16, "rw", False), (0x6060, 0, I8, "rww", True), (0x6061, 0, I8, "ro", True),
    (0x6064, 0, I32, "ro", True), (0x6065, 0, U32, "rw", False), (0x6066, 0, U16, "rw", False),
    (0x606C, 0, I32, "ro", True), (0x6076, 0, U32, "rw", False), (0x6077, 0, I16, "ro", True),
    (0x607A, 0, I32, "rww", True), (0x607C, 0, I32, "rw", False), (0x607D, 1, I32, "rw", False),
    (0x607D, 2, I32, "rw", False), (0x6081, 0, U32, "rww", True), (0x6083, 0, U32, "rw", False),
    (0x6084, 0, U32, "rw", False), (0x6085, 0, U32, "rw", False), (0x6098, 0, I8, "rw", False),
    (0x6099, 1, U32, "rw", False), (0x6099, 2, U32, "rw", False), (0x60F4, 0, I32, "ro", True),
    (0x6502, 0, U32, "ro", False),
])
def test_object_types_access_and_mapping(od, index, subindex, data_type, access, mappable):
    variable = entry(od, index, subindex)
    assert (variable.data_type, variable.access_type, variable.pdo_mappable) == (data_type, access, mappable)


def test_pdo_communication_defaults_use_the_node_id(od):
    assert [entry(od, 0x1400 + n, 1).default for n in range(4)] == [0x203, 0x80000303, 0x80000403, 0x80000503]
    assert [entry(od, 0x1800 + n, 1).default for n in range(4)] == [
        0x40000183, 0xC0000283, 0xC0000383, 0xC0000483]
    assert entry(od, 0x1800, 2).default == 1          # TPDO1 on every SYNC
    assert all(entry(od, index, subindex).writable
               for index in (*range(0x1400, 0x1404), *range(0x1800, 0x1804)) for subindex in (1, 2))
    assert all(entry(od, index, subindex).writable
               for index in (*range(0x1600, 0x1604), *range(0x1A00, 0x1A04)) for subindex in range(9))


def test_default_mappings(od):
    def mapping(index):
        return [entry(od, index, s).default for s in range(1, entry(od, index, 0).default + 1)]
    assert mapping(0x1600) == [0x60400010, 0x607A0020]                 # controlword, target position
    assert mapping(0x1A00) == [0x60410010, 0x60640020, 0x60770010]     # statusword, position, torque
    assert [entry(od, index, 0).default for index in (0x1601, 0x1602, 0x1603, 0x1A01, 0x1A02, 0x1A03)] == [0] * 6


def test_supported_modes_and_device_type(od):
    assert entry(od, 0x6502).default == 0b1010_0001     # PP (bit 0), HM (bit 5), CSP (bit 7)
    assert entry(od, 0x1000).default == 0x00020192      # CiA 402, servo drive


def test_local_and_remote_node_load_it():
    local = canopen.LocalNode(7, str(EDS_PATH))
    remote = canopen.RemoteNode(7, str(EDS_PATH))
    assert local.sdo[0x1018][1].raw == 0x43525354
    assert remote.object_dictionary[0x1A00][1].default == 0x60410010
    assert local.tpdo.map[1].com_record[1].raw == 0x40000187
