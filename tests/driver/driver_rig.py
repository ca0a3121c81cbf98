"""Test rig: simulated drives (sim_backend) and a Testbed on a private virtual CAN channel.

Time: the testbed runs on a SteppedClock whose every step ticks the simulated drive set, so
heartbeats, heartbeat timeouts and scheduled faults happen in simulated time, and the drives
move one cycle per SYNC the driver sends. Nothing sleeps; replies are waited for on conditions.
A recorder on a third bus instance sees every frame in the order it was sent.
"""

from __future__ import annotations

import struct
import threading
import uuid
from dataclasses import replace

import can

from crest.config import TestbedConfig, load_testbed_config
from crest.driver import SteppedClock, Testbed
from sim_backend.drive.drive_spec import DriveSpec
from sim_backend.drives import SimDriveSet

WAIT_S = 2.0
#: Where the insertion carriage stands at power-up: 1 mm above its limit switch (home, 20 mm).
INSERTION_START_MM = 21.0
#: An identifier no node uses: the rig's marker frame (see Rig.frames).
MARKER_COB_ID = 0x7FF
STOPPED_STATES = {"QUICK_STOP_ACTIVE", "SWITCH_ON_DISABLED", "FAULT"}


def make_config(**master_overrides) -> TestbedConfig:
    """configs/testbed.toml, with ``master_overrides`` replacing fields of its [master] table.

    The SDO and boot timeouts are wall time: the simulated drives answer from their own thread,
    which a loaded machine can hold back for well over 0.1 s. Only a test that expects the timeout
    to expire should shorten it.
    """
    config = load_testbed_config()
    return replace(config, master=replace(config.master, **master_overrides))


def drive_specs(config: TestbedConfig, insertion_start_mm: float = INSERTION_START_MM) -> list[DriveSpec]:
    """One simulated drive per configured axis, with the axis' scaling and limits.

    An axis homing on its negative limit switch (method 17) gets the switch at its home position.
    """
    specs = []
    for axis in config.axes:
        specs.append(DriveSpec(
            name=axis.name, node_id=axis.node_id, eds_path=axis.eds_path,
            encoder_counts_per_rev=axis.encoder_counts_per_rev, gear_ratio=axis.gear_ratio,
            drum_radius_mm=axis.drum_radius_mm, soft_limits_mm=axis.soft_limits_mm, homing_method=axis.homing_method,
            max_velocity_mm_s=axis.max_velocity_mm_s, max_acceleration_mm_s2=axis.max_acceleration_mm_s2,
            rated_torque_mnm=axis.rated_torque_mnm, following_error_window_mm=axis.following_error_window_mm,
            home_position_mm=axis.home_position_mm,
            negative_limit_switch_mm=axis.home_position_mm if axis.homing_method == 17 else None,
            start_position_mm=insertion_start_mm if axis.kind == "insertion" else 0.0,
            master_node_id=config.master.node_id, heartbeat_period_s=config.master.drive_heartbeat_period_s,
            heartbeat_timeout_s=config.master.heartbeat_timeout_s, cycle_period_s=config.sync.period_s))
    return specs


class FrameRecorder(can.Listener):
    """Every frame on the channel, in the order they were sent."""

    def __init__(self) -> None:
        self.frames: list[can.Message] = []
        self.arrived = threading.Condition()

    def on_message_received(self, msg: can.Message) -> None:
        with self.arrived:
            self.frames.append(msg)
            self.arrived.notify_all()

    def snapshot(self) -> list[can.Message]:
        with self.arrived:
            return list(self.frames)

    def wait_for(self, predicate, what: str) -> None:
        with self.arrived:
            if not self.arrived.wait_for(lambda: predicate(self.frames), timeout=WAIT_S):
                raise AssertionError(f"timed out waiting for {what}")

    def stop(self) -> None:
        """Listener interface: nothing to release."""


class Rig:
    """Simulated drives, a Testbed on a stepped clock, and a recorder of every frame, on one channel."""

    def __init__(self, config: TestbedConfig, specs: list[DriveSpec], faults=()) -> None:
        self.config = config
        self.channel = f"crest-driver-{uuid.uuid4().hex}"
        self.recorder = FrameRecorder()
        self._recorder_bus = can.Bus(interface="virtual", channel=self.channel)
        self._recorder_notifier = can.Notifier(self._recorder_bus, [self.recorder], timeout=0.05)
        self.drives = SimDriveSet(specs, self.channel, faults=faults)
        self.drives.start()
        self.bus = can.Bus(interface="virtual", channel=self.channel)
        self.clock = SteppedClock(on_advance=self.drives.tick)
        self.testbed = Testbed(self.bus, config, clock=self.clock)

    def frames(self) -> list[can.Message]:
        """Every frame sent so far: a marker frame goes out last and is waited for (no frame overtakes it)."""
        self.bus.send(can.Message(arbitration_id=MARKER_COB_ID, data=b"", is_extended_id=False))
        marks = sum(f.arbitration_id == MARKER_COB_ID for f in self.recorder.snapshot()) + 1
        self.recorder.wait_for(lambda frames: sum(f.arbitration_id == MARKER_COB_ID for f in frames) >= marks,
                               "the marker frame")
        return [f for f in self.recorder.snapshot() if f.arbitration_id != MARKER_COB_ID]

    def drive(self, name: str):
        return self.drives.drive(name)

    def advance(self, duration_s: float) -> None:
        """Let simulated time pass with the host silent (no heartbeat, no SYNC)."""
        self.clock.advance(duration_s)

    def drive_states(self) -> dict[str, str]:
        return {name: drive.state.name for name, drive in self.drives.drives.items()}

    def close(self) -> None:
        self.testbed.close()
        self.drives.stop()
        self.bus.shutdown()
        self._recorder_notifier.stop()
        self._recorder_bus.shutdown()




# --- reading the recorded frames ---------------------------------------------------------------
SYNC_COB_ID = 0x80


def is_sync(frame: can.Message) -> bool:
    return not frame.is_error_frame and frame.arbitration_id == SYNC_COB_ID


def rpdo1(frame: can.Message, node_id: int) -> tuple[int, int] | None:
    """(controlword, target position counts) of an RPDO1 to ``node_id`` (mapping of testbed.toml)."""
    if frame.is_error_frame or frame.arbitration_id != 0x200 + node_id:
        return None
    return struct.unpack("<Hi", bytes(frame.data))


def tpdo1(frame: can.Message, node_id: int) -> tuple[int, int, int] | None:
    """(statusword, position actual counts, torque actual per mille) of a TPDO1 from ``node_id``."""
    if frame.is_error_frame or frame.arbitration_id != 0x180 + node_id:
        return None
    return struct.unpack("<Hih", bytes(frame.data))


def sdo_downloads(frames: list[can.Message], node_id: int) -> list[tuple[int, int, int]]:
    """(index, subindex, value) of every expedited SDO download request to ``node_id``, in order.

    CiA 301 initiate download request: byte 0 = 0x20 | n << 2 | e 0x02 | s 0x01, where n is the
    number of data bytes 4..7 that carry no data; bytes 1-2 index, byte 3 subindex.
    """
    writes = []
    for frame in frames:
        data = bytes(frame.data)
        if frame.is_error_frame or frame.arbitration_id != 0x600 + node_id or data[0] & 0xE3 != 0x23:
            continue
        unused = (data[0] >> 2) & 0x03
        writes.append((int.from_bytes(data[1:3], "little"), data[3], int.from_bytes(data[4:8 - unused], "little")))
    return writes
