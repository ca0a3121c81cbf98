"""Test bench: simulated drives on a fresh virtual CAN channel, and canopen as an independent client.

Synchronisation without sleeps: the drives run in their network's notifier
thread and answer frames in arrival order, and the client's notifier handles
replies in arrival order too. So once an SDO upload to any drive of the set has
returned, every frame the client sent before it has been processed by the
drives and every frame they sent in reply has reached the client's callbacks.
``barrier`` does exactly that round trip.
"""

from __future__ import annotations

import uuid
from dataclasses import replace
from pathlib import Path

import can
import canopen
from canopen.profiles.p402 import BaseNode402

from sim_backend.drive.drive_spec import DriveSpec
from sim_backend.drives import SimDriveSet
from tests.frame_recorder import FrameRecorder

EDS_PATH = Path(__file__).resolve().parents[2] / "configs" / "crest_drive.eds"
MASTER_NODE_ID = 127
WAIT_S = 2.0


def tendon_spec(name: str = "tendon1", node_id: int = 1, **overrides) -> DriveSpec:
    """A tendon-shaft drive with the testbed.toml tendon defaults."""
    spec = DriveSpec(name=name, node_id=node_id, eds_path=EDS_PATH, encoder_counts_per_rev=4096,
                     gear_ratio=10.0, drum_radius_mm=5.0, soft_limits_mm=(-12.0, 12.0), homing_method=37,
                     max_velocity_mm_s=20.0, max_acceleration_mm_s2=200.0, rated_torque_mnm=1000.0,
                     following_error_window_mm=1.0, master_node_id=MASTER_NODE_ID)
    return replace(spec, **overrides)


def insertion_spec(name: str = "insertion", node_id: int = 5, **overrides) -> DriveSpec:
    """The pulley-block drive with the testbed.toml insertion defaults and its limit switch at home."""
    spec = DriveSpec(name=name, node_id=node_id, eds_path=EDS_PATH, encoder_counts_per_rev=4096,
                     gear_ratio=20.0, drum_radius_mm=8.0, soft_limits_mm=(20.0, 100.0), homing_method=17,
                     max_velocity_mm_s=10.0, max_acceleration_mm_s2=100.0, rated_torque_mnm=1000.0,
                     following_error_window_mm=1.0, home_position_mm=20.0, negative_limit_switch_mm=20.0,
                     start_position_mm=30.0, master_node_id=MASTER_NODE_ID)
    return replace(spec, **overrides)


class DriveBench:
    """Drives for ``specs`` plus a client network with a BaseNode402 per drive."""

    def __init__(self, specs: list[DriveSpec], faults=()) -> None:
        self.channel = f"crest-test-{uuid.uuid4().hex}"
        self.recorder = FrameRecorder(WAIT_S)
        self.client = canopen.Network()
        self.client.listeners.append(self.recorder)
        self.client.NOTIFIER_CYCLE = 0.05  # short shutdown
        self.client.connect(interface="virtual", channel=self.channel)
        self.nodes: dict[str, BaseNode402] = {}
        for spec in specs:
            node = BaseNode402(spec.node_id, str(EDS_PATH))
            self.client.add_node(node)
            self.nodes[spec.name] = node
        self.drive_set = SimDriveSet(specs, self.channel, faults=faults)
        self.drive_set.start()
        self.now_s = 0.0

    def close(self) -> None:
        self.drive_set.stop()
        self.client.disconnect()

    def drive(self, name: str):
        return self.drive_set.drive(name)

    def barrier(self, name: str | None = None) -> None:
        """SDO round trip to a drive: everything sent before is processed and answered."""
        node = self.nodes[name] if name else next(iter(self.nodes.values()))
        node.sdo.upload(0x1000, 0)

    def sync(self, count: int = 1, barrier_via: str | None = None) -> None:
        """Send SYNC frames, each followed by a barrier (the drives step one cycle per SYNC)."""
        for _ in range(count):
            self.client.sync.transmit()
            self.barrier(barrier_via)

    def tick(self, now_s: float) -> None:
        self.now_s = now_s
        self.drive_set.tick(now_s)

    def master_heartbeat(self, barrier_via: str | None = None) -> None:
        """One heartbeat of the master (node 127, OPERATIONAL) followed by a barrier."""
        self.client.send_message(0x700 + MASTER_NODE_ID, bytes([0x05]))
        self.barrier(barrier_via)

    def operational(self, name: str) -> BaseNode402:
        """TPDO/RPDO maps read from the drive by SDO, then NMT start; returns the client node."""
        node = self.nodes[name]
        node.tpdo.read()
        node.rpdo.read()
        node.nmt.send_command(0x01)
        self.barrier(name)
        return node

    def enable(self, name: str, mode: int) -> BaseNode402:
        """OPERATIONAL, mode of operation set, and OPERATION ENABLED (by SDO)."""
        node = self.operational(name)
        node.sdo[0x6060].raw = mode
        self.controlword(name, 0x06)
        assert self.controlword(name, 0x0F) & 0x6F == 0x27, "drive did not reach OPERATION ENABLED"
        return node

    def tpdo1(self, name: str) -> dict[int, int]:
        """Last TPDO1 the client received from a drive, decoded by canopen: {index: value}."""
        return {variable.index: variable.raw for variable in self.nodes[name].tpdo[1].map}

    def controlword(self, name: str, value: int) -> int:
        """Write 0x6040 by SDO and read back the statusword 0x6041 by SDO."""
        node = self.nodes[name]
        node.sdo[0x6040].raw = value
        return node.sdo[0x6041].raw
