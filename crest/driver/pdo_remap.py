"""PDO configuration by SDO, the CiA 301 way, and its verification.

Communication parameter 0x1400+n (RPDO) / 0x1800+n (TPDO): sub 1 COB-ID (bit 31 set: PDO not
valid; bit 30 set: no remote request), sub 2 transmission type. Mapping parameter 0x1600+n /
0x1A00+n: sub 0 number of entries, sub 1..8 entries. A drive accepts a new mapping only in
this order (CiA 301 7.5.2.36):

    1. COB-ID with bit 31 set (PDO not valid)
    2. mapping sub 0 = 0
    3. mapping sub 1..n = entries
    4. mapping sub 0 = n
    5. transmission type
    6. COB-ID with bit 31 clear (valid again)

Everything is read back afterwards; a difference raises ReadBackMismatch naming the PDO and
the sub-index. PDOs 2..4 are switched off so that only RPDO1/TPDO1 load the bus.
"""

from __future__ import annotations

from dataclasses import dataclass

from crest.driver.drive_axis import RPDO_TRANSMISSION_TYPE, TPDO_TRANSMISSION_TYPE, DriveAxis
from crest.driver.errors import ReadBackMismatch
from crest.driver.pdo_layout import PdoLayout

PDO_NOT_VALID = 1 << 31
NO_RTR = 1 << 30
PDO_COUNT = 4
RPDO_COMMUNICATION, RPDO_MAPPING = 0x1400, 0x1600
TPDO_COMMUNICATION, TPDO_MAPPING = 0x1800, 0x1A00


@dataclass(frozen=True)
class PdoPlan:
    """What one PDO must look like: where its parameters are and what they must hold."""

    label: str
    communication_index: int
    mapping_index: int
    cob_id: int
    transmission_type: int
    layout: PdoLayout


def pdo_plans(axis: DriveAxis) -> tuple[PdoPlan, PdoPlan]:
    """RPDO1 and TPDO1 of an axis, as the driver uses them."""
    return (PdoPlan("RPDO1", RPDO_COMMUNICATION, RPDO_MAPPING, axis.rpdo_cob_id, RPDO_TRANSMISSION_TYPE, axis.rpdo),
            PdoPlan("TPDO1", TPDO_COMMUNICATION, TPDO_MAPPING, axis.tpdo_cob_id | NO_RTR, TPDO_TRANSMISSION_TYPE,
                    axis.tpdo))


def remap(axis: DriveAxis, plan: PdoPlan) -> None:
    """Write one PDO in the order of the module docstring."""
    step = f"remap {plan.label}"
    sdo, comm, mapping = axis.sdo, plan.communication_index, plan.mapping_index
    current_cob_id = sdo.read(comm, 1, step)
    sdo.write(comm, 1, current_cob_id | PDO_NOT_VALID, f"{step}: disable")
    sdo.write(mapping, 0, 0, f"{step}: clear mapping")
    for subindex, entry in enumerate(plan.layout.mapping_entries, start=1):
        sdo.write(mapping, subindex, entry, f"{step}: map entry {subindex}")
    sdo.write(mapping, 0, len(plan.layout.mapping_entries), f"{step}: number of entries")
    sdo.write(comm, 2, plan.transmission_type, f"{step}: transmission type")
    sdo.write(comm, 1, plan.cob_id, f"{step}: enable")


def verify(axis: DriveAxis, plan: PdoPlan) -> None:
    """Read the PDO back; ReadBackMismatch names what differs."""
    step = f"verify {plan.label}"
    sdo, comm, mapping = axis.sdo, plan.communication_index, plan.mapping_index
    expected = [(comm, 1, plan.cob_id, "COB-ID"), (comm, 2, plan.transmission_type, "transmission type"),
                (mapping, 0, len(plan.layout.mapping_entries), "number of mapped objects")]
    expected += [(mapping, subindex, entry, f"mapping entry {subindex}")
                 for subindex, entry in enumerate(plan.layout.mapping_entries, start=1)]
    for index, subindex, value, what in expected:
        actual = sdo.read(index, subindex, step)
        if actual != value:
            raise ReadBackMismatch(axis.name, f"{plan.label} {what} 0x{index:04X}:{subindex:02X} reads back "
                                              f"0x{actual:08X}, expected 0x{value:08X}; the drive did not take the "
                                              "mapping: check rpdo1/tpdo1 against the drive's manual")


def disable_unused(axis: DriveAxis) -> None:
    """Mark RPDO2..4 and TPDO2..4 not valid (and check they read so)."""
    for base, kind in ((RPDO_COMMUNICATION, "RPDO"), (TPDO_COMMUNICATION, "TPDO")):
        for number in range(2, PDO_COUNT + 1):
            index = base + number - 1
            step = f"disable {kind}{number}"
            cob_id = axis.sdo.read(index, 1, step)
            if not cob_id & PDO_NOT_VALID:
                axis.sdo.write_verified(index, 1, cob_id | PDO_NOT_VALID, step)


def configure_pdos(axis: DriveAxis) -> None:
    """Switch unused PDOs off, remap RPDO1 and TPDO1, and verify both."""
    disable_unused(axis)
    for plan in pdo_plans(axis):
        remap(axis, plan)
        verify(axis, plan)
