"""``crest estop``: quick-stop every drive from a process that is not the master.

Controlword 0x6040 = 0x02 (quick stop) by SDO to each drive, then the statusword is read to
report its state. With quick stop option code 2 (set at boot) the drive ramps down and ends in
SWITCH ON DISABLED, and the master's enable-operation controlwords cannot re-enable it; the
master sees the axis leave OPERATION ENABLED and stops the whole testbed.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

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
    """Quick stop to every axis at once; per axis the state it shows afterwards, or the SDO failure.

    Each axis has its own SDO channel, so the axes are stopped concurrently (one thread each): a
    drive that does not answer delays no other by its SDO timeout, and every quick stop is on the
    bus before the master, seeing the first axis stop, ends its run (and with it a testbed it owns).
    The bus is left open for its owner.
    """
    network = canopen.Network(bus)
    network.NOTIFIER_CYCLE = RECEIVE_POLL_S
    network.connect()
    try:
        axes = [config.axis(name) for name in AXIS_ORDER]
        channels = {axis.name: AxisSdo(axis.name, network.add_node(axis.node_id, str(axis.eds_path)),
                                       config.master.sdo_timeout_s) for axis in axes}
        with ThreadPoolExecutor(max_workers=len(channels), thread_name_prefix="crest-estop") as pool:
            outcomes = pool.map(_quick_stop, channels.values())
            return dict(zip(channels, outcomes))
    finally:
        network.notifier.stop()


def _quick_stop(sdo: AxisSdo) -> Cia402State | SdoFailure:
    """Controlword quick stop, then the state the statusword shows; or the SDO failure."""
    try:
        sdo.write(CONTROLWORD, 0, cia402.QUICK_STOP, "emergency stop: quick stop")
        return cia402.state_from_statusword(sdo.read(STATUSWORD, 0, "emergency stop: read state"))
    except SdoFailure as failure:
        return failure
