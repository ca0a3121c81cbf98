"""The virtual testbed: five simulated CiA 402 drives, the plant behind them, the simulated tracker.

The crest driver opens `can.Bus(interface="virtual", channel=testbed.channel)` and the serial
port `testbed.tracker_port` exactly as it would open hardware.

Coupling, on every SYNC (after all drives have advanced one cycle): the tendon and insertion
drives' actual positions go to the plant; the plant's tendon tensions go back to the tendon
drives, which report them as torque actual (0x6077) from the next cycle. A plant slower than
the bus runs in its own thread instead, and the drives use its latest output. The tracker samples
the tip once the SYNC being handled has stepped the plant: a master that asks for a frame as soon
as the drives have answered a SYNC sees the tip of that SYNC, not a race between the two threads
(so a recording in simulated time gives the same rows every time).

Time: the drives' motion advances by SYNC frames. Time-based duties (heartbeats, watchdogs,
scheduled faults) advance with `tick(now_s)`: called by the tests with simulated time, by a
real-time thread when `start(realtime=True)`, or by the TIME stamps a master in another process
sends on the bus when `start(time_stamps=True)` (sim_backend.time_stamps).
"""
from __future__ import annotations

import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass

from sim_backend.drive.drive_spec import DriveSpec
from sim_backend.drives import SimDriveSet
from sim_backend.faults import FaultSchedule, FaultSpec
from sim_backend.plant import Plant, PlantError, PlantRunner
from sim_backend.time_stamps import follow_time_stamps
from sim_backend.tracker import SimTracker

TENDON_AXES = ("tendon1", "tendon2", "tendon3", "tendon4")
INSERTION_AXIS = "insertion"
REALTIME_TICK_S = 0.005
SYNC_HANDLED_TIMEOUT_S = 1.0    # how long a tracker sample waits for the plant's step of a SYNC


@dataclass(frozen=True)
class TrackerSettings:
    noise_mm: float = 0.05
    dropout: float = 0.0
    seed: int = 1
    tool_handle: int = 0x0A


class VirtualTestbed:
    def __init__(self, drive_specs: Sequence[DriveSpec], channel: str, plant: Plant, *,
                 sync_period_s: float = 0.01,
                 tracker: TrackerSettings = TrackerSettings(), faults: Sequence[FaultSpec] = (),
                 faults_wait_for_run: bool = False, plant_in_thread: bool = False):
        names = {spec.name for spec in drive_specs}
        missing = set(TENDON_AXES + (INSERTION_AXIS,)) - names
        if missing:
            raise ValueError(f"the virtual testbed needs drives named {sorted(missing)}")
        self.channel = channel
        self.sync_period_s = sync_period_s
        self.drives = SimDriveSet(drive_specs, channel, faults=faults, faults_held=faults_wait_for_run)
        self._tracker_faults = FaultSchedule([f for f in faults if f.targets_tracker], held=faults_wait_for_run)
        self.plant_runner = PlantRunner(plant, self._tendon_positions_mm(), self._insertion_position_mm())
        self.plant_in_thread = plant_in_thread
        self.tracker = SimTracker(self._tracker_tip, noise_mm=tracker.noise_mm, dropout=tracker.dropout,
                                  seed=tracker.seed, tool_handle=tracker.tool_handle)
        self.syncs_seen = 0
        self._ticker: threading.Thread | None = None
        self._stop = threading.Event()
        self._started_s = 0.0
        self._now_s = 0.0          # the last tick's time (s since start)

    # -- life cycle ---------------------------------------------------------------------------
    def start(self, realtime: bool = False, time_stamps: bool = False) -> "VirtualTestbed":
        """Start the drives, the plant and the tracker. Time: realtime, a thread ticks the testbed on
        the wall clock; time_stamps, every TIME stamp on the bus moves it (sim_backend.time_stamps);
        neither, the caller ticks it."""
        if realtime and time_stamps:
            raise ValueError("a virtual testbed keeps one clock: real time or the bus's TIME stamps, not both")
        self.drives.start()
        self.drives.add_sync_listener(self._on_sync)
        # in simulated time a tracker frame is a function of the plant's step it samples (SimTracker.draw_key)
        self.tracker.draw_key = None if realtime else (lambda: self.syncs_seen)
        if time_stamps:
            follow_time_stamps(self.drives, self.tick, self.start_fault_clock)
        self.tracker.start()
        if self.plant_in_thread:
            self.plant_runner.start_thread()
        self._started_s = time.monotonic()
        if realtime:
            self._stop.clear()
            self._ticker = threading.Thread(target=self._tick_in_real_time, name="testbed-clock", daemon=True)
            self._ticker.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        if self._ticker is not None:
            self._ticker.join(timeout=2.0)
            self._ticker = None
        self.plant_runner.stop_thread()
        self.tracker.stop()
        self.drives.stop()

    def __enter__(self) -> "VirtualTestbed":
        return self.start()

    def __exit__(self, *exc_info) -> None:
        self.stop()

    # -- what the host opens ------------------------------------------------------------------
    @property
    def tracker_port(self) -> str:
        return self.tracker.port_name

    # -- time ---------------------------------------------------------------------------------
    def start_fault_clock(self) -> None:
        """Scheduled faults count from now (the last tick), when the testbed was built with
        faults_wait_for_run; the first call counts, later ones change nothing."""
        self.drives.start_fault_clock(self._now_s)
        self._tracker_faults.start_clock(self._now_s)

    def tick(self, now_s: float) -> None:
        """Time-based duties at now_s (s since start): drive heartbeats and watchdogs, faults."""
        self._now_s = now_s
        self.drives.tick(now_s)
        for fault in self._tracker_faults.due(now_s):
            self.tracker.inject(fault.kind.value)

    def _tick_in_real_time(self) -> None:
        while not self._stop.wait(REALTIME_TICK_S):
            self.tick(time.monotonic() - self._started_s)

    # -- plant coupling -----------------------------------------------------------------------
    def _tendon_positions_mm(self) -> list[float]:
        return [self.drives.drive(name).position_actual_mm for name in TENDON_AXES]

    def _insertion_position_mm(self) -> float:
        return self.drives.drive(INSERTION_AXIS).position_actual_mm

    def _on_sync(self, can_id: int, data: bytearray, timestamp: float) -> None:
        self.syncs_seen += 1
        self.plant_runner.set_inputs(self._tendon_positions_mm(), self._insertion_position_mm())
        if not self.plant_in_thread:
            try:
                self.plant_runner.step(self.sync_period_s)
            except PlantError as exc:
                self.plant_runner.error = exc
        _, tension_n = self.plant_runner.latest()
        for name, tension in zip(TENDON_AXES, tension_n):
            self.drives.drive(name).set_load_tension_n(float(tension))

    def _tracker_tip(self):
        self.drives.wait_sync_handled(SYNC_HANDLED_TIMEOUT_S)
        if self.plant_runner.error is not None:
            return None
        return self.plant_runner.tip_mm()

    # -- reports ------------------------------------------------------------------------------
    def true_tip_mm(self):
        """The plant's tip, as the tracker would see it without noise or dropout."""
        return self.plant_runner.tip_mm()

    @property
    def plant_rate_hz(self) -> float:
        """Steps per second the plant achieved (in thread mode), else SYNCs per second."""
        return self.plant_runner.achieved_rate_hz
