"""The set of simulated drives on one virtual CAN bus.

All drives share one python-can ``virtual`` bus instance and one canopen.Network
(its notifier thread runs their callbacks). A client (the crest driver, or
canopen.RemoteNode / BaseNode402 in tests) opens its own
``can.Bus(interface="virtual", channel=<same channel>)`` and talks to them as to
hardware. Whoever wants the bus load feeds a ``sim_backend.bus_load.BusLoadMeter`` from the
frames it sees (`crest bench` taps the host's own handle, crest.driver.hooked_bus): every further
handle on the bus costs each frame a copy and a thread wake-up, so the drives keep none for it.

``tick(now_s)`` (s since the testbed started) drives the drives' time-based
duties and fires scheduled per-axis faults; SYNC frames from the client drive
their motion. SYNC listeners run after every drive has handled a SYNC, in the
same thread, so a plant stepped there is coupled cycle by cycle: its output
(``set_load_tension_n``) goes out in the TPDOs of the next SYNC. The drives' TPDOs leave before
those listeners run, so a master can act on a SYNC's answers while the plant still steps for it;
``wait_sync_handled`` waits that step out (the tracker's sample is taken after it).
"""

from __future__ import annotations

import threading
from typing import Callable, Iterable, Sequence

import can
import canopen

from sim_backend.drive.drive_spec import DriveSpec
from sim_backend.drive.sim_drive import SYNC_COB_ID, SimDrive
from sim_backend.faults import FaultSchedule, FaultSpec, check_fault_axes


#: Receive poll period of the notifier threads (s): how long ``stop`` may wait for them.
NOTIFIER_POLL_S = 0.05


class SimDriveSet:
    """Drives for ``specs`` on the virtual CAN channel ``channel``.

    :param faults: per-axis faults to inject at their time; tracker faults are ignored here.
    :param faults_held: their clock waits for ``start_fault_clock`` (see ``FaultSchedule``).
    """

    def __init__(self, specs: Sequence[DriveSpec], channel: str, *, faults: Iterable[FaultSpec] = (),
                 faults_held: bool = False) -> None:
        _check_unique(specs)
        self.channel = channel
        self.drives: dict[str, SimDrive] = {spec.name: SimDrive(spec) for spec in specs}
        drive_faults = [fault for fault in faults if not fault.targets_tracker]
        check_fault_axes(drive_faults, list(self.drives))
        self._schedule = FaultSchedule(drive_faults, held=faults_held)
        self._sync_listeners: list[Callable[[int, bytearray, float], None]] = []
        self._network: canopen.Network | None = None
        self._sync_handled = threading.Condition()
        self._syncs_begun = 0
        self._syncs_handled = 0

    def drive(self, name: str) -> SimDrive:
        try:
            return self.drives[name]
        except KeyError:
            raise KeyError(f"no drive named {name!r}; drives are {', '.join(self.drives)}") from None

    def add_sync_listener(self, listener: Callable[[int, bytearray, float], None]) -> None:
        """Call ``listener(can_id, data, timestamp)`` (canopen's subscriber signature) for each
        SYNC frame, after every drive has run its cycle for it."""
        self._sync_listeners.append(listener)

    def subscribe(self, cob_id: int, callback: Callable[[int, bytearray, float], None]) -> None:
        """Call ``callback(can_id, data, timestamp)`` for each frame with this COB-ID, in the drives'
        receive thread (so in order with the frames the drives handle); after ``start``."""
        self._network.subscribe(cob_id, callback)

    def send(self, msg: can.Message) -> None:
        """Send a frame on the drives' bus (from any thread); after ``start``."""
        self._network.send_message(msg.arbitration_id, msg.data)

    def wait_sync_handled(self, timeout_s: float) -> bool:
        """Wait until the SYNC the drives are handling (if any) is handled to its last listener;
        False if that took over ``timeout_s`` (e.g. a listener failed)."""
        with self._sync_handled:
            return self._sync_handled.wait_for(lambda: self._syncs_handled == self._syncs_begun, timeout_s)

    def _on_sync_begin(self, can_id: int, data: bytearray, timestamp: float) -> None:
        with self._sync_handled:
            self._syncs_begun += 1

    def _on_sync(self, can_id: int, data: bytearray, timestamp: float) -> None:
        try:
            for listener in self._sync_listeners:
                listener(can_id, data, timestamp)
        finally:
            with self._sync_handled:
                self._syncs_handled = self._syncs_begun
                self._sync_handled.notify_all()

    def start(self) -> None:
        """Open the bus, attach the drives and power them on (each sends its boot-up message)."""
        self._network = canopen.Network(can.Bus(interface="virtual", channel=self.channel))
        self._network.NOTIFIER_CYCLE = NOTIFIER_POLL_S
        self._network.connect()
        self._network.subscribe(SYNC_COB_ID, self._on_sync_begin)  # before the drives' own SYNC handlers
        for drive in self.drives.values():
            drive.attach(self._network)
        self._network.subscribe(SYNC_COB_ID, self._on_sync)  # after the drives' own SYNC handlers
        for drive in self.drives.values():
            drive.power_on()

    def stop(self) -> None:
        """Close the bus instances (the drives fall silent)."""
        if self._network is not None:
            self._network.disconnect()
            self._network = None

    def __enter__(self) -> SimDriveSet:
        self.start()
        return self

    def __exit__(self, *exc_info) -> None:
        self.stop()

    def start_fault_clock(self, now_s: float) -> None:
        self._schedule.start_clock(now_s)

    def tick(self, now_s: float) -> None:
        """Time-based duties at ``now_s`` (s since start): scheduled faults, heartbeats, watchdogs."""
        for fault in self._schedule.due(now_s):
            self.drives[fault.axis].inject_fault(fault.kind)
        for drive in self.drives.values():
            drive.tick(now_s)


def _check_unique(specs: Sequence[DriveSpec]) -> None:
    names = [spec.name for spec in specs]
    node_ids = [spec.node_id for spec in specs]
    for label, values in (("name", names), ("node id", node_ids)):
        duplicates = sorted({value for value in values if values.count(value) > 1}, key=str)
        if duplicates:
            raise ValueError(f"drives must have distinct {label}s; repeated: {duplicates}")
