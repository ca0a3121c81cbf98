"""Test rig: the simulated drives in a process of their own, and a Testbed that meets them across
the process boundary, on the bus the drives' process serves over python-can-remote (127.0.0.1).

Time: the testbed runs on a SteppedClock. Each step sends a CANopen TIME stamp that moves the
drives' process to that time (sim_backend.time_stamps, as a `--fast` command drives a testbed
served in simulated time) and waits for the drives' answer, so heartbeats, heartbeat timeouts and
scheduled faults happen in simulated time, in step with the master, and the drives move one cycle
per SYNC the driver sends. Nothing sleeps; replies are waited for on conditions.

A recorder, a third client of the bus, sees every frame in the order the bus carried it. The test
reads the drives and breaks them through the rig (`drive_states`, `inject_fault`, ...), which asks
the drives' process (drive_process.py) once the drives have handled every frame sent before.
"""

from __future__ import annotations

import multiprocessing
import struct
from dataclasses import replace

import can

import drive_process
from crest.config import TestbedConfig, load_testbed_config
from crest.driver import SteppedClock, Testbed
from crest.testbed_service.served_bus import ServedBus
from drive_process import MARKER_COB_ID, MARKER_ECHO_COB_ID, serve_drives
from sim_backend.drive.drive_spec import DriveSpec
from sim_backend.faults import FaultKind
from sim_backend.time_stamps import TIME_ACK_COB_ID, time_stamp_frame
from tests.frame_recorder import FrameRecorder

#: Wall time a reply may take: the drives' process answers from its own threads, which a loaded
#: 2-core machine can hold back for well over 0.1 s.
WAIT_S = 10.0
#: Wall time the drives' process may take to start (a fresh interpreter importing canopen).
START_TIMEOUT_S = 60.0
#: Where the insertion carriage stands at power-up: 1 mm above its limit switch (home, 20 mm).
INSERTION_START_MM = 21.0
#: Wall time a simulated drive may take to answer an SDO on a loaded machine (as tests/serve's relaxed timing).
LOADED_SDO_TIMEOUT_S = 2.0
STOPPED_STATES = {"QUICK_STOP_ACTIVE", "SWITCH_ON_DISABLED", "FAULT"}


def make_config(**master_overrides) -> TestbedConfig:
    """configs/testbed.toml, with ``master_overrides`` replacing fields of its [master] table, and
    the SDO timeout LOADED_SDO_TIMEOUT_S unless overridden.

    The SDO and boot timeouts are wall time: the simulated drives answer from their own process,
    which a loaded machine can hold back for well over 0.1 s, and past the configured 0.5 s once
    (a boot's identity read, `pytest -n 3` on two cores, 2026-12-07). Only a test that expects the
    timeout to expire should shorten it.
    """
    config = load_testbed_config()
    master = {"sdo_timeout_s": LOADED_SDO_TIMEOUT_S, **master_overrides}
    return replace(config, master=replace(config.master, **master))


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


class Rig:
    """The drives of `specs` in their own process, a Testbed on a stepped clock, and a recorder of
    every frame, all on the bus the drives' process serves."""

    def __init__(self, config: TestbedConfig, specs: list[DriveSpec], faults=()) -> None:
        self.config = config
        self.drive_names = [spec.name for spec in specs]
        context = multiprocessing.get_context("spawn")
        self._requests, child_end = context.Pipe()
        self._process = context.Process(target=serve_drives, args=(specs, list(faults), child_end),
                                        name="driver-rig-drives", daemon=True)
        self._process.start()
        child_end.close()
        if not self._requests.poll(START_TIMEOUT_S):
            self._process.kill()
            raise AssertionError(f"the drives' process did not start within {START_TIMEOUT_S:g} s")
        self.bus_url = self._requests.recv()
        self.recorder = FrameRecorder(WAIT_S)
        self._recorder_bus = ServedBus(self.bus_url)
        self._recorder_notifier = can.Notifier(self._recorder_bus, [self.recorder], timeout=0.05)
        self.bus = ServedBus(self.bus_url)
        self.frames()          # the recorder's handle is on the bus before the master sends anything
        self.clock = SteppedClock(on_advance=self._move_drives_to)
        self.testbed = Testbed(self.bus, config, clock=self.clock)

    def _move_drives_to(self, now_s: float) -> None:
        """Send the TIME stamp of now_s and wait for the drives' answer to it."""
        stamp = time_stamp_frame(now_s)
        after = len(self.recorder.snapshot())
        self.bus.send(stamp)
        self.recorder.wait_for_frame(lambda frame: frame.arbitration_id == TIME_ACK_COB_ID and frame.data == stamp.data,
                                     after, f"the drives' answer to the time stamp of {now_s:g} s")

    def open_bus(self) -> can.BusABC:
        """Another client's handle on the rig's bus (shut it down after use)."""
        return ServedBus(self.bus_url)

    def frames(self) -> list[can.Message]:
        """Every frame sent so far, the drives' answers included: a marker frame goes out on the
        master's handle and the drives' process echoes it once it has handled every frame before
        it (drive_process.py); the echo is waited for."""
        marker = can.Message(arbitration_id=MARKER_COB_ID, data=b"", is_extended_id=False)
        after = len(self.recorder.snapshot())
        self.bus.send(marker)
        self.recorder.wait_for_frame(lambda frame: frame.arbitration_id == MARKER_ECHO_COB_ID, after,
                                     "the drives' echo of the marker frame")
        return [f for f in self.recorder.snapshot() if f.arbitration_id not in (MARKER_COB_ID, MARKER_ECHO_COB_ID)]

    def in_drives(self, request, *args):
        """`request(drives, *args)` (a module-level function) run in the drives' process, after
        they handled every frame sent; what it returns, or what it raised, raised here."""
        self.frames()
        self._requests.send((request, args))
        if not self._requests.poll(WAIT_S):
            raise AssertionError(f"the drives' process did not answer {request.__name__} within {WAIT_S:g} s")
        succeeded, result = self._requests.recv()
        if not succeeded:
            raise result
        return result

    # --- what the test reads and breaks in the drives ------------------------------------------
    def drive_states(self) -> dict[str, str]:
        return self.in_drives(drive_process.drive_states)

    def nmt_states(self) -> dict[str, str]:
        return self.in_drives(drive_process.nmt_states)

    def position_actual_mm(self, name: str) -> float:
        return self.in_drives(drive_process.position_actual_mm, name)

    def object_value(self, name: str, index: int, subindex: int = 0) -> int:
        """The value of object index:subindex in the drive's own object dictionary."""
        return self.in_drives(drive_process.object_value, name, index, subindex)

    def active_error_codes(self, name: str) -> tuple[int, ...]:
        return self.in_drives(drive_process.active_error_codes, name)

    def inject_fault(self, name: str, kind: FaultKind) -> None:
        self.in_drives(drive_process.inject_fault, name, kind)

    def set_load_tension_n(self, name: str, tension_n: float) -> None:
        self.in_drives(drive_process.set_load_tension_n, name, tension_n)

    def advance(self, duration_s: float) -> None:
        """Let simulated time pass with the host silent (no heartbeat, no SYNC)."""
        self.clock.advance(duration_s)

    def close(self) -> None:
        try:
            self.testbed.close()
        finally:
            self.bus.shutdown()
            self._recorder_notifier.stop()
            self._recorder_bus.shutdown()
            self._requests.close()            # the drives' process ends when its pipe closes
            self._process.join(WAIT_S)
            if self._process.is_alive():
                self._process.kill()
                self._process.join()


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
