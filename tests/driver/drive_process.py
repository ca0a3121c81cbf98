"""The driver rig's second process: the simulated drives, served on a real inter-process CAN bus.

`serve_drives` runs in a process of its own (started by driver_rig.Rig). It starts the drives of
`specs` on an in-process virtual channel and serves that channel on 127.0.0.1 over
python-can-remote (sim_backend.bus_server), exactly as `crest testbed serve` does, so the master
under test meets the drives across a process boundary. Its clock moves only with the TIME stamps
the master's stepped clock sends (sim_backend.time_stamps), as a testbed served in simulated time.

Two more services, for the test only:
- A marker frame (MARKER_COB_ID) from the master is echoed on MARKER_ECHO_COB_ID from the drives'
  receive thread. The drives handle frames in order and send their own frames from that thread,
  so once the echo arrives, the drives have handled every frame the master sent before the marker
  and every frame they sent because of it is on the bus.
- The pipe from the rig carries requests `(function, args)`: the process calls
  `function(drives, *args)` (a module-level function, pickled by name) and sends back
  `(True, result)`, or `(False, exception)` if it raised. This is the test's hand inside the
  drives: it reads their state and injects faults, as a technician would at the machine. The
  process ends when the rig closes the pipe.
"""
from __future__ import annotations

import uuid
from collections.abc import Sequence
from multiprocessing.connection import Connection

import can

from sim_backend.bus_server import BusServer
from sim_backend.drive.drive_spec import DriveSpec
from sim_backend.drives import SimDriveSet
from sim_backend.faults import FaultKind, FaultSpec
from sim_backend.time_stamps import follow_time_stamps

MARKER_COB_ID = 0x7FF         # no node uses these two identifiers
MARKER_ECHO_COB_ID = 0x7FE


def serve_drives(specs: Sequence[DriveSpec], faults: Sequence[FaultSpec], requests: Connection) -> None:
    """Serve the drives until `requests` is closed; the bus's URL goes out first on `requests`."""
    drives = SimDriveSet(specs, f"crest-driver-{uuid.uuid4().hex}", faults=faults)
    drives.start()
    follow_time_stamps(drives, drives.tick)
    drives.subscribe(MARKER_COB_ID, lambda can_id, data, timestamp: drives.send(
        can.Message(arbitration_id=MARKER_ECHO_COB_ID, data=bytes(data), is_extended_id=False)))
    server = BusServer(drives.channel).start()
    try:
        requests.send(server.url)
        while True:
            try:
                function, args = requests.recv()
            except EOFError:
                return
            try:
                requests.send((True, function(drives, *args)))
            except Exception as exc:
                requests.send((False, exc))
    finally:
        server.stop()
        drives.stop()


# --- requests (each runs in the drives' process) -----------------------------------------------
def drive_states(drives: SimDriveSet) -> dict[str, str]:
    return {name: drive.state.name for name, drive in drives.drives.items()}


def nmt_states(drives: SimDriveSet) -> dict[str, str]:
    return {name: drive.nmt_state for name, drive in drives.drives.items()}


def position_actual_mm(drives: SimDriveSet, name: str) -> float:
    return drives.drive(name).position_actual_mm


def object_value(drives: SimDriveSet, name: str, index: int, subindex: int) -> int:
    return drives.drive(name).node.value(index, subindex)


def active_error_codes(drives: SimDriveSet, name: str) -> tuple[int, ...]:
    return drives.drive(name).active_error_codes


def inject_fault(drives: SimDriveSet, name: str, kind: FaultKind) -> None:
    drives.drive(name).inject_fault(kind)


def set_load_tension_n(drives: SimDriveSet, name: str, tension_n: float) -> None:
    drives.drive(name).set_load_tension_n(tension_n)
