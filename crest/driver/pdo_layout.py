"""The layout of one PDO: which objects, in which order, with which EDS data types.

CiA 301 mapping entry (0x1600+n / 0x1A00+n sub 1..8), UNSIGNED32:

    entry = index << 16 | subindex << 8 | length in bits

The mapped objects fill the frame's data bytes in mapping order, each little endian in its
EDS data type. The driver maps whole bytes only (every object it uses is 8, 16 or 32 bits).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from canopen.objectdictionary import ObjectDictionary, ODVariable

from crest.config import PdoEntry
from crest.driver.errors import DriveError


def mapping_entry(entry: PdoEntry) -> int:
    """The UNSIGNED32 mapping entry of a PdoEntry."""
    return entry.index << 16 | entry.subindex << 8 | entry.bits


class PdoLayout:
    """Packs and unpacks the frames of one PDO (``label`` e.g. ``"RPDO1"``) of axis ``axis``."""

    def __init__(self, axis: str, label: str, entries: Sequence[PdoEntry], od: ObjectDictionary) -> None:
        self.label = label
        self.entries = tuple(entries)
        self._variables: list[tuple[PdoEntry, ODVariable]] = []
        for entry in self.entries:
            variable = od.get_variable(entry.index, entry.subindex)
            where = f"{label} entry 0x{entry.index:04X}:{entry.subindex:02X}"
            if variable is None:
                raise DriveError(axis, f"{where} is not in the drive's EDS; map objects the drive has")
            if len(variable) != entry.bits or entry.bits % 8:
                raise DriveError(axis, f"{where} is mapped with {entry.bits} bits but the EDS gives it "
                                       f"{len(variable)}; set the length to {len(variable)}")
            self._variables.append((entry, variable))
        indices = [entry.index for entry in self.entries]
        if len(set(indices)) != len(indices):
            raise DriveError(axis, f"{label} maps an object twice ({indices}); map each object once")
        self.length_bytes = sum(entry.bits for entry in self.entries) // 8

    @property
    def mapping_entries(self) -> tuple[int, ...]:
        return tuple(mapping_entry(entry) for entry in self.entries)

    @property
    def indices(self) -> frozenset[int]:
        return frozenset(entry.index for entry in self.entries)

    def pack(self, values: Mapping[int, int]) -> bytes:
        """Frame data from {object index: value}; every mapped object needs a value."""
        return b"".join(variable.encode_raw(values[entry.index]) for entry, variable in self._variables)

    def unpack(self, data: bytes) -> dict[int, int]:
        """{object index: value} from frame data of exactly ``length_bytes``; ValueError otherwise."""
        if len(data) != self.length_bytes:
            raise ValueError(f"{self.label} has {len(data)} data bytes, its mapping needs {self.length_bytes}")
        values = {}
        offset = 0
        for entry, variable in self._variables:
            size = entry.bits // 8
            values[entry.index] = variable.decode_raw(bytes(data[offset:offset + size]))
            offset += size
        return values
