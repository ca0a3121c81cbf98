"""One CiA 402 drive as the host commands and sees it: RPDO1 out, TPDO1 in, SDO for the rest.

Every SYNC cycle the host sends RPDO1 (controlword 0x6040, target position 0x607A) and the
drive answers the SYNC with TPDO1 (statusword 0x6041, position actual 0x6064, torque actual
0x6077). RPDO1 is event driven (transmission type 255): the drive acts on a controlword as it
arrives, so a quick stop does not wait for a SYNC, while in cyclic synchronous position mode
the drive still latches 0x607A at the SYNC. TPDO1 is synchronous (type 1): sampled and sent at
every SYNC.

Halt (controlword bit 8) is set from the moment the axis is enabled until a valid target has
been given for the current mode; ``command`` keeps it so.
"""

from __future__ import annotations

import threading

import canopen

from crest.config import AxisConfig
from crest.driver import cia402
from crest.driver.axis_sdo import AxisSdo
from crest.driver.cia402 import Cia402State, OperationMode
from crest.driver.errors import DriveError, ReadBackMismatch
from crest.driver.pdo_layout import PdoLayout

CONTROLWORD = 0x6040
STATUSWORD = 0x6041
MODES_OF_OPERATION = 0x6060
MODES_OF_OPERATION_DISPLAY = 0x6061
POSITION_ACTUAL = 0x6064
TORQUE_ACTUAL = 0x6077
TARGET_POSITION = 0x607A
FOLLOWING_ERROR_ACTUAL = 0x60F4
ERROR_CODE = 0x603F

RPDO1_COB_ID_BASE = 0x200
TPDO1_COB_ID_BASE = 0x180
RPDO_TRANSMISSION_TYPE = 255  # event driven: acted on when received
TPDO_TRANSMISSION_TYPE = 1    # synchronous: sent at every SYNC

_RPDO_OBJECTS = frozenset({CONTROLWORD, TARGET_POSITION})


class DriveAxis:
    """The drive of one axis. ``feedback_changed`` is shared by all axes of a testbed.

    Feedback attributes are written by the CAN notifier thread (``on_tpdo``) under
    ``feedback_changed``; command attributes belong to the thread that runs the SYNC cycle.
    """

    def __init__(self, config: AxisConfig, node: canopen.RemoteNode, sdo_timeout_s: float,
                 feedback_changed: threading.Condition) -> None:
        self.config = config
        self.name = config.name
        self.node = node
        self.sdo = AxisSdo(config.name, node, sdo_timeout_s)
        self.rpdo = PdoLayout(config.name, "RPDO1", config.rpdo1, node.object_dictionary)
        self.tpdo = PdoLayout(config.name, "TPDO1", config.tpdo1, node.object_dictionary)
        extra = self.rpdo.indices - _RPDO_OBJECTS
        if extra:
            raise DriveError(self.name, f"RPDO1 maps {', '.join(f'0x{i:04X}' for i in sorted(extra))}, which the "
                                        "driver does not write; map only 0x6040 and 0x607A")
        self.rpdo_cob_id = RPDO1_COB_ID_BASE + config.node_id
        self.tpdo_cob_id = TPDO1_COB_ID_BASE + config.node_id
        # feedback (notifier thread)
        self.feedback_changed = feedback_changed
        self.tpdo_count = 0
        self.tpdo_values: dict[int, int] = {}
        self.tpdo_error: str | None = None
        # command (cycle thread)
        self.controlword = cia402.DISABLE_VOLTAGE
        self.target_counts = 0
        self.sent_target_counts = 0  # the target of the last RPDO1 sent: latched at the last SYNC
        self.halted = True
        self.mode: OperationMode | None = None
        self.profile_counts: tuple[int, int] | None = None  # last 0x6081 and 0x6083/0x6084 written
        self.must_be_enabled = False

    # --- process data ------------------------------------------------------------------
    def on_tpdo(self, can_id: int, data: bytearray, timestamp: float) -> None:
        """TPDO1 received (notifier thread)."""
        with self.feedback_changed:
            try:
                self.tpdo_values = self.tpdo.unpack(bytes(data))
            except ValueError as error:
                self.tpdo_error = str(error)
            self.tpdo_count += 1
            self.feedback_changed.notify_all()

    def rpdo_data(self, controlword: int | None = None) -> bytes:
        """RPDO1 data with the axis' command (or another controlword, e.g. a quick stop)."""
        word = self.controlword if controlword is None else controlword
        return self.rpdo.pack({CONTROLWORD: word, TARGET_POSITION: self.target_counts})

    def command(self, controlword: int, *, halt: bool | None = None) -> None:
        """Set the controlword sent from the next cycle on.

        Bit 8 (halt) follows ``halted`` (set it with ``halt``) on enable-operation words; the
        state-machine words of the other states go out exactly as given (a fault reset is 0x00
        then 0x80).
        """
        if halt is not None:
            self.halted = halt
        enabling = controlword & 0x0F == cia402.ENABLE_OPERATION
        self.controlword = controlword | (cia402.HALT if enabling and self.halted else 0)

    @property
    def statusword(self) -> int:
        with self.feedback_changed:
            return self.tpdo_values.get(STATUSWORD, 0)

    @property
    def state(self) -> Cia402State:
        return cia402.state_from_statusword(self.statusword)

    @property
    def position_counts(self) -> int:
        with self.feedback_changed:
            return self.tpdo_values.get(POSITION_ACTUAL, 0)

    @property
    def position_mm(self) -> float:
        return self.config.counts_to_mm(self.position_counts)

    @property
    def torque_permille(self) -> int:
        with self.feedback_changed:
            return self.tpdo_values.get(TORQUE_ACTUAL, 0)

    @property
    def tension_n(self) -> float:
        """Tendon tension (or axial load) in N from torque actual, see AxisConfig.tension_n_per_permille."""
        return self.config.tension_n_from_torque_permille(self.torque_permille)

    @property
    def target_mm(self) -> float:
        return self.config.counts_to_mm(self.target_counts)

    def has_status(self, bits: int) -> bool:
        return self.statusword & bits == bits

    # --- service data --------------------------------------------------------------------
    def set_mode(self, mode: OperationMode) -> None:
        """Write modes of operation 0x6060 and check the display 0x6061 follows."""
        step = f"select {mode.name.lower().replace('_', ' ')} mode"
        self.sdo.write(MODES_OF_OPERATION, 0, int(mode), step)
        shown = self.sdo.read(MODES_OF_OPERATION_DISPLAY, 0, step)
        if shown != int(mode):
            raise ReadBackMismatch(self.name, f"{step}: 0x6060 = {int(mode)} written but the drive shows mode "
                                              f"{shown} in 0x6061; the drive refused the mode change")
        self.mode = mode
