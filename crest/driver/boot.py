"""Boot sequence, SDO part: NMT reset, boot-up, identity, configuration, PDO mapping, heartbeat.

1. NMT reset node (command 0x81) to each drive, then wait for every boot-up message
   (boot_timeout_s): the drives start from their power-on state, faults cleared;
2. identity 0x1000 / 0x1018 / 0x6502 against the EDS (identity.py);
3. parameters by SDO, each read back (drive_parameters.py), profile position mode selected;
4. PDOs: unused ones off, RPDO1 and TPDO1 remapped the CiA 301 way and read back (pdo_remap.py);
5. last, each drive's heartbeat consumer 0x1016 set to watch the host.

The testbed then starts the host heartbeat and SYNC and sends NMT start (testbed.py).
"""

from __future__ import annotations

from collections.abc import Sequence

from crest.config import TestbedConfig
from crest.driver.cia402 import OperationMode
from crest.driver.drive_axis import DriveAxis
from crest.driver.drive_parameters import write_heartbeat_consumer, write_parameters
from crest.driver.errors import BootError
from crest.driver.heartbeat_consumer import HeartbeatConsumer
from crest.driver.identity import DriveIdentity, check_identity
from crest.driver.pdo_remap import configure_pdos

NMT_RESET_NODE = 0x81


def reset_and_configure(axes: Sequence[DriveAxis], heartbeats: HeartbeatConsumer,
                        config: TestbedConfig) -> dict[str, DriveIdentity]:
    """Steps 1-5 of the module docstring; returns each axis' identity."""
    heartbeats.forget_boot_ups()
    for axis in axes:
        axis.node.nmt.send_command(NMT_RESET_NODE)
    missing = heartbeats.wait_for_boot_ups(config.master.boot_timeout_s)
    if missing:
        raise BootError(missing[0], f"no boot-up message (COB-ID 0x{0x700 + config.axis(missing[0]).node_id:03X}) "
                                    f"within boot_timeout_s {config.master.boot_timeout_s:g} s after NMT reset node "
                                    f"(silent: {', '.join(missing)}); check power, node id and bitrate "
                                    f"{config.bus.bitrate} bit/s")
    identities = {}
    for axis in axes:
        identities[axis.name] = check_identity(axis)
        write_parameters(axis, config)
        axis.set_mode(OperationMode.PROFILE_POSITION)
        configure_pdos(axis)
    for axis in axes:
        write_heartbeat_consumer(axis, config)
    return identities
