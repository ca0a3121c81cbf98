"""Process data objects of a drive (CiA 301 section 7.2.2): TPDO on SYNC, RPDO into the dictionary.

Communication parameter (0x1400+n RPDO, 0x1800+n TPDO): sub 1 COB-ID (bit 31 set:
PDO not valid, bit 30 set: no RTR), sub 2 transmission type:
    0        synchronous, acyclic: a TPDO is sent at the SYNC after its data changed;
             an RPDO is applied at the next SYNC
    1..240   synchronous, cyclic: a TPDO is sent at every n-th SYNC;
             an RPDO is applied at the next SYNC
    254, 255 event driven: a TPDO is sent when its data change; an RPDO is applied at once
Mapping parameter (0x1600+n RPDO, 0x1A00+n TPDO): sub 0 number of entries, sub 1..8
entries (index << 16 | subindex << 8 | length in bits), at most 64 bits in total.

Reconfiguration follows CiA 301: a mapping may only be written while the PDO is
not valid and its sub 0 is 0, and a valid PDO's COB-ID may not change. A write
that breaks a rule is answered with the SDO abort code of CiA 301 table 22.

Only the maps are kept in canopen's PdoMap objects; this class decides when
they are sent or applied.
"""

from __future__ import annotations

import struct
from typing import Callable

from canopen.pdo import PdoMap
from canopen.sdo import SdoAbortedError

from sim_backend.drive.drive_node import DriveNode

PDO_NOT_VALID = 1 << 31
EXTENDED_FRAME = 1 << 29
RPDO_COMM, RPDO_MAP, TPDO_COMM, TPDO_MAP = 0x1400, 0x1600, 0x1800, 0x1A00
PDO_COUNT = 4
MAX_PDO_BITS = 64
MAX_ENTRIES = 8
VALID_TRANSMISSION_TYPES = frozenset(range(0, 241)) | {254, 255}

ABORT_VALUE_RANGE = 0x06090030
ABORT_DEVICE_STATE = 0x08000022
ABORT_NOT_IN_OD = 0x06020000
ABORT_SUBINDEX = 0x06090011
ABORT_NOT_MAPPABLE = 0x06040041
ABORT_PDO_LENGTH = 0x06040042


def _in_block(index: int, base: int) -> bool:
    return base <= index < base + PDO_COUNT


def is_pdo_parameter(index: int) -> bool:
    return any(_in_block(index, base) for base in (RPDO_COMM, RPDO_MAP, TPDO_COMM, TPDO_MAP))


def decode_mapping_entry(entry: int) -> tuple[int, int, int]:
    """(index, subindex, length in bits) of a mapping entry."""
    return entry >> 16, (entry >> 8) & 0xFF, entry & 0xFF


class ProcessData:
    """Sends the drive's TPDOs and applies its RPDOs.

    :param send: transmits (cob_id, data); the drive gates it.
    :param on_rpdo: the drive's entry for a received RPDO (it locks, checks the NMT
        state and then calls ``receive``).
    :param on_length_error: called when an RPDO is shorter than its mapping (EMCY 0x8210).
    """

    def __init__(self, node: DriveNode, send: Callable[[int, bytes], None],
                 on_rpdo: Callable[[PdoMap], None], on_length_error: Callable[[], None]) -> None:
        self._node = node
        self._send = send
        self._on_rpdo = on_rpdo
        self._on_length_error = on_length_error
        self._sync_count: dict[int, int] = {}
        self._last_sent: dict[int, bytes] = {}
        self._pending_rpdo: dict[int, bytes] = {}
        # canopen's PdoMaps is a Mapping walked key by key; its maps are made once, with the node
        self._rpdo_maps = tuple(node.rpdo.map.maps.values())
        self._tpdo_maps = tuple(node.tpdo.map.maps.values())

    # --- configuration -------------------------------------------------------------
    def load(self) -> None:
        """Read every PDO's configuration from the dictionary (after boot or reset)."""
        self._pending_rpdo.clear()
        for pdo_map in self._all_maps():
            self._reload(pdo_map)

    def on_config_written(self, index: int) -> None:
        """A communication or mapping parameter was written: re-read that PDO."""
        for base_comm, base_map, maps in ((RPDO_COMM, RPDO_MAP, self._node.rpdo.map),
                                          (TPDO_COMM, TPDO_MAP, self._node.tpdo.map)):
            for base in (base_comm, base_map):
                if _in_block(index, base):
                    self._reload(maps[index - base + 1])

    def _all_maps(self) -> list[PdoMap]:
        return [*self._rpdo_maps, *self._tpdo_maps]

    def _reload(self, pdo_map: PdoMap) -> None:
        network = self._node.network
        if pdo_map.cob_id is not None and pdo_map.on_message in network.subscribers.get(pdo_map.cob_id, []):
            network.unsubscribe(pdo_map.cob_id, pdo_map.on_message)
        pdo_map.read()  # subscribes valid maps for reception
        key = id(pdo_map)
        self._sync_count[key] = 0
        self._last_sent.pop(key, None)
        self._pending_rpdo.pop(key, None)
        is_tpdo = pdo_map in self._tpdo_maps
        if is_tpdo and pdo_map.enabled:
            network.unsubscribe(pdo_map.cob_id, pdo_map.on_message)
        if not is_tpdo and self._on_rpdo not in pdo_map.callbacks:
            pdo_map.add_callback(self._on_rpdo)

    # --- write validation (runs before the value is stored) ------------------------
    def validate_write(self, index: int, subindex: int, data: bytes) -> None:
        """Raise SdoAbortedError for a PDO parameter write that CiA 301 forbids."""
        if _in_block(index, RPDO_COMM) or _in_block(index, TPDO_COMM):
            self._validate_communication(index, subindex, data)
        elif _in_block(index, RPDO_MAP) or _in_block(index, TPDO_MAP):
            self._validate_mapping(index, subindex, data)

    def _validate_communication(self, index: int, subindex: int, data: bytes) -> None:
        if subindex == 1:
            (new,) = struct.unpack("<I", data)
            old = self._node.value(index, 1)
            if new & EXTENDED_FRAME:
                raise SdoAbortedError(ABORT_VALUE_RANGE)
            if not old & PDO_NOT_VALID and not new & PDO_NOT_VALID and (old ^ new) & 0x7FF:
                raise SdoAbortedError(ABORT_VALUE_RANGE)
        elif subindex == 2 and data[0] not in VALID_TRANSMISSION_TYPES:
            raise SdoAbortedError(ABORT_VALUE_RANGE)

    def _validate_mapping(self, index: int, subindex: int, data: bytes) -> None:
        comm_index = index - (RPDO_MAP - RPDO_COMM)
        if not self._node.value(comm_index, 1) & PDO_NOT_VALID:
            raise SdoAbortedError(ABORT_DEVICE_STATE)
        is_rpdo = _in_block(index, RPDO_MAP)
        if subindex == 0:
            count = data[0]
            if count > MAX_ENTRIES:
                raise SdoAbortedError(ABORT_VALUE_RANGE)
            bits = sum(decode_mapping_entry(self._node.value(index, s))[2] for s in range(1, count + 1))
            if bits > MAX_PDO_BITS:
                raise SdoAbortedError(ABORT_PDO_LENGTH)
            return
        if self._node.value(index, 0) != 0:
            raise SdoAbortedError(ABORT_DEVICE_STATE)
        (entry,) = struct.unpack("<I", data)
        if entry == 0:
            return
        mapped_index, mapped_subindex, length = decode_mapping_entry(entry)
        if mapped_index not in self._node.object_dictionary:
            raise SdoAbortedError(ABORT_NOT_IN_OD)
        try:
            variable = self._node.od_variable(mapped_index, mapped_subindex)
        except KeyError:
            raise SdoAbortedError(ABORT_SUBINDEX) from None
        accessible = variable.writable if is_rpdo else variable.readable
        if not variable.pdo_mappable or not accessible or length != len(variable):
            raise SdoAbortedError(ABORT_NOT_MAPPABLE)

    # --- reception -----------------------------------------------------------------
    def receive(self, pdo_map: PdoMap) -> bool:
        """Apply a received RPDO now (event driven: True) or keep it for the next SYNC (False)."""
        if len(pdo_map.data) * 8 < pdo_map.length:
            self._on_length_error()
            return False
        if pdo_map.trans_type is not None and pdo_map.trans_type <= 240:
            self._pending_rpdo[id(pdo_map)] = bytes(pdo_map.data)
            return False
        self._write_mapped(pdo_map)
        return True

    def _write_mapped(self, pdo_map: PdoMap) -> None:
        for variable in pdo_map.map:
            self._node.set_data(variable.index, variable.subindex, variable.get_data())

    def apply_synchronous_rpdos(self) -> None:
        """At a SYNC: write the synchronous RPDOs received during the last cycle."""
        for pdo_map in self._rpdo_maps:
            data = self._pending_rpdo.pop(id(pdo_map), None)
            if data is not None:
                pdo_map.data = bytearray(data)
                self._write_mapped(pdo_map)

    # --- transmission ----------------------------------------------------------------
    def _sample(self, pdo_map: PdoMap) -> bytes:
        for variable in pdo_map.map:
            variable.set_data(self._node.get_data(variable.index, variable.subindex))
        return bytes(pdo_map.data)

    def transmit_on_sync(self) -> None:
        """At a SYNC: send the synchronous TPDOs that are due (types 0 and 1..240)."""
        for pdo_map in self._tpdo_maps:
            if not pdo_map.enabled or pdo_map.trans_type is None or pdo_map.trans_type > 240:
                continue
            key = id(pdo_map)
            data = self._sample(pdo_map)
            if pdo_map.trans_type == 0:
                due = data != self._last_sent.get(key)
            else:
                self._sync_count[key] = self._sync_count.get(key, 0) + 1
                due = self._sync_count[key] >= pdo_map.trans_type
            if due:
                self._sync_count[key] = 0
                self._last_sent[key] = data
                self._send(pdo_map.cob_id, data)

    def transmit_changed(self) -> None:
        """Send the event-driven TPDOs (types 254, 255) whose data changed."""
        for pdo_map in self._tpdo_maps:
            if not pdo_map.enabled or pdo_map.trans_type is None or pdo_map.trans_type < 254:
                continue
            key = id(pdo_map)
            data = self._sample(pdo_map)
            if data != self._last_sent.get(key):
                self._last_sent[key] = data
                self._send(pdo_map.cob_id, data)
