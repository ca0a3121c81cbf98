"""The drive's CANopen node: canopen's LocalNode with a ticked NMT slave and a write hook.

canopen.LocalNode supplies the object dictionary (from the EDS), the SDO server
and the PDO maps. Two things are changed:

- its NmtSlave is replaced by ``TickedNmtSlave`` (heartbeat by ``tick``, boot-up
  on received resets). LocalNode registers the old slave's 0x1017 write hook in
  its private callback list, so that hook is swapped as well;
- ``set_data`` reports each completed write (SDO download or RPDO) to the drive,
  because LocalNode's own write callbacks run *before* the value is stored.
"""

from __future__ import annotations

from typing import Callable

from canopen import LocalNode, objectdictionary

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

    def set_data(self, index: int, subindex: int, data: bytes, check_writable: bool = False) -> None:
        super().set_data(index, subindex, data, check_writable)
        self._on_written(index, subindex)

    def od_variable(self, index: int, subindex: int = 0) -> objectdictionary.ODVariable:
        """The dictionary entry of index:subindex (KeyError if the EDS lacks it)."""
        entry = self.object_dictionary[index]
        if isinstance(entry, objectdictionary.ODVariable):
            return entry
        return entry[subindex]

    def value(self, index: int, subindex: int = 0) -> int:
        """Current value of an object (stored, else the EDS default), decoded."""
        return self.od_variable(index, subindex).decode_raw(self.get_data(index, subindex))

    def store(self, index: int, subindex: int, value: int) -> None:
        """Set an object from inside the drive, without the SDO write hooks."""
        data = self.od_variable(index, subindex).encode_raw(value)
        self.data_store.setdefault(index, {})[subindex] = bytes(data)
