"""``crest estop``: quick-stop every drive from a process that is not the master.

Controlword 0x6040 = 0x02 (quick stop) by SDO to each drive, then the statusword is read to
report its state. With quick stop option code 2 (set at boot) the drive ramps down and ends in
SWITCH ON DISABLED, and the master's enable-operation controlwords cannot re-enable it; the
master sees the axis leave OPERATION ENABLED and stops the whole testbed.
"""

from __future__ import annotations

import can
import canopen

from crest.config import TestbedConfig
from crest.driver import cia402
from crest.driver.axis_sdo import AxisSdo
from crest.driver.axis_targets import AXIS_ORDER
from crest.driver.cia402 import Cia402State
from crest.driver.drive_axis import CONTROLWORD, STATUSWORD
from crest.driver.errors import SdoFailure

RECEIVE_POLL_S = 0.1  # longest the receive thread blocks before it can end


def emergency_stop(bus: can.BusABC, config: TestbedConfig) -> dict[str, Cia402State | SdoFailure]:
    """Quick stop to every axis; per axis the state it shows afterwards, or the SDO failure.

    Every axis is tried even if one fails; the bus is left open for its owner.
    """
    network = canopen.Network(bus)
    network.NOTIFIER_CYCLE = RECEIVE_POLL_S
    network.connect()
    outcome: dict[str, Cia402State | SdoFailure] = {}
    try:
        for name in AXIS_ORDER:
            axis = config.axis(name)
            sdo = AxisSdo(name, network.add_node(axis.node_id, str(axis.eds_path)), config.master.sdo_timeout_s)
            try:
                sdo.write(CONTROLWORD, 0, cia402.QUICK_STOP, "emergency stop: quick stop")
                outcome[name] = cia402.state_from_statusword(sdo.read(STATUSWORD, 0, "emergency stop: read state"))
            except SdoFailure as failure:
                outcome[name] = failure
    finally:
        network.notifier.stop()
    return outcome
