"""The drive's CANopen node: canopen's LocalNode with a ticked NMT slave and a write hook.

canopen.LocalNode supplies the object dictionary (from the EDS), the SDO server
and the PDO maps. Two things are changed:

- its NmtSlave is replaced by ``TickedNmtSlave`` (heartbeat by ``tick``, boot-up
  on received resets). LocalNode registers the old slave's 0x1017 write hook in
  its private callback list, so that hook is swapped as well;
- ``set_data`` reports each completed write (SDO download or RPDO) to the drive,
  because LocalNode's own write callbacks run *before* the value is stored;
- the lookup of an entry (``_find_object``) is remembered: the dictionary does not change once
  loaded, and the drive reads and writes its process objects several times per SYNC. So is the
  value of the bytes in store (``value``, ``store``): a value is decoded or encoded again only once
  other bytes are in store (this node has no read callbacks that could change what is read).
"""

from __future__ import annotations

from typing import Callable

from canopen import LocalNode, objectdictionary
from canopen.sdo import SdoAbortedError

from sim_backend.drive.nmt_slave import TickedNmtSlave


class DriveNode(LocalNode):
    """LocalNode of a simulated drive.

    :param on_written: called with (index, subindex) after a value was stored.
    :param on_reset: called with the NMT reset command (0x81 or 0x82) before boot-up.
    :param send: transmits (cob_id, data) for the NMT slave.
    """

    def __init__(self, node_id: int, eds_path: str,
                 on_written: Callable[[int, int], None],
                 on_reset: Callable[[int], None],
                 send: Callable[[int, bytes], None]) -> None:
        super().__init__(node_id, eds_path)
        self._write_callbacks.remove(self.nmt.on_write)
        self.nmt = TickedNmtSlave(node_id, self, on_reset=on_reset, send=send)
        self.add_write_callback(self.nmt.on_write)
        self._on_written = on_written
        self._found: dict[tuple[int, int], objectdictionary.ODVariable] = {}
        self._known: dict[tuple[int, int], tuple[int, bytes]] = {}   # a value and the bytes in store for it

    def set_data(self, index: int, subindex: int, data: bytes, check_writable: bool = False) -> None:
        super().set_data(index, subindex, data, check_writable)
        self._on_written(index, subindex)

    def _find_object(self, index: int, subindex: int) -> objectdictionary.ODVariable:
        """LocalNode's lookup (SdoAbortedError if the EDS lacks the entry), remembered once found."""
        key = (index, subindex)
        found = self._found.get(key)
        if found is None:
            found = self._found[key] = super()._find_object(index, subindex)
        return found

    def od_variable(self, index: int, subindex: int = 0) -> objectdictionary.ODVariable:
        """The dictionary entry of index:subindex (KeyError if the EDS lacks it)."""
        try:
            return self._find_object(index, subindex)
        except SdoAbortedError:
            raise KeyError(f"0x{index:04X}:{subindex:02X}") from None

    def value(self, index: int, subindex: int = 0) -> int:
        """Current value of an object (stored, else the EDS default), decoded; not decoded again
        while the bytes in store are the ones decoded last time."""
        key = (index, subindex)
        known = self._known.get(key)
        if known is not None and self.data_store.get(index, {}).get(subindex) is known[1]:
            return known[0]
        data = self.get_data(index, subindex)
        value = self.od_variable(index, subindex).decode_raw(data)
        self._known[key] = (value, data)
        return value

    def store(self, index: int, subindex: int, value: int) -> None:
        """Set an object from inside the drive, without the SDO write hooks. The value that is in
        store already (most process objects keep theirs from one SYNC to the next) is not encoded
        again."""
        key = (index, subindex)
        objects = self.data_store.setdefault(index, {})
        known = self._known.get(key)
        if known is not None and known[0] == value and objects.get(subindex) is known[1]:
            return
        data = bytes(self.od_variable(index, subindex).encode_raw(value))
        objects[subindex] = data
        self._known[key] = (value, data)
