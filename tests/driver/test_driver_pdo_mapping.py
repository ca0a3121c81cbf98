"""PDO mapping: written the CiA 301 way, read back, and a wrong read-back is caught."""

import pytest

from crest.driver import ReadBackMismatch
from crest.driver.pdo_layout import mapping_entry
from driver_rig import sdo_downloads


def test_drives_carry_the_configured_mappings_and_transmission_types(booted):
    for axis in booted.config.axes:
        def value(index, subindex=0, name=axis.name):
            return booted.object_value(name, index, subindex)
        rpdo = [value(0x1600, sub) for sub in range(1, value(0x1600, 0) + 1)]
        tpdo = [value(0x1A00, sub) for sub in range(1, value(0x1A00, 0) + 1)]
        assert rpdo == [mapping_entry(entry) for entry in axis.rpdo1] == [0x60400010, 0x607A0020]
        assert tpdo == [mapping_entry(entry) for entry in axis.tpdo1] == [0x60410010, 0x60640020, 0x60770010]
        assert value(0x1400, 1) == 0x200 + axis.node_id and value(0x1400, 2) == 255   # event driven
        assert value(0x1800, 1) == 0x40000180 + axis.node_id and value(0x1800, 2) == 1  # every SYNC
        for index in (0x1401, 0x1402, 0x1403, 0x1801, 0x1802, 0x1803):
            assert value(index, 1) & 0x80000000, f"{axis.name}: 0x{index:04X} should be off"


def test_tpdo1_is_remapped_in_the_cia_301_order(booted):
    writes = [w for w in sdo_downloads(booted.frames(), 3) if w[0] in (0x1800, 0x1A00)]
    assert writes == [
        (0x1800, 1, 0xC0000183),   # 1. not valid (bit 31), no RTR (bit 30) kept
        (0x1A00, 0, 0),            # 2. no entries
        (0x1A00, 1, 0x60410010),   # 3. statusword
        (0x1A00, 2, 0x60640020),   #    position actual
        (0x1A00, 3, 0x60770010),   #    torque actual
        (0x1A00, 0, 3),            # 4. three entries
        (0x1800, 2, 1),            # 5. synchronous, every SYNC
        (0x1800, 1, 0x40000183),   # 6. valid again
    ]


def map_following_error_for_position(drives, name: str) -> None:
    """In the drives' process: drive `name` puts following error actual (0x60F4) where position
    actual is asked for in its TPDO1 mapping."""
    node = drives.drive(name).node
    store = node.set_data

    def maps_something_else(index, subindex, data, check_writable=False):
        if (index, subindex) == (0x1A00, 2):
            data = (0x60F40020).to_bytes(4, "little")
        store(index, subindex, data, check_writable)

    node.set_data = maps_something_else


def test_a_mapping_that_reads_back_different_stops_the_boot(make_rig):
    rig = make_rig()
    rig.in_drives(map_following_error_for_position, "tendon2")
    with pytest.raises(ReadBackMismatch) as error:
        rig.testbed.boot()
    message = str(error.value)
    assert error.value.axis == "tendon2"
    assert "TPDO1 mapping entry 2 0x1A00:02 reads back 0x60F40020, expected 0x60640020" in message
    assert rig.nmt_states()["tendon2"] == "PRE-OPERATIONAL"   # never started
