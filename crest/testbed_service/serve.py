"""Serving the virtual testbed as its own process, until it is told to stop.

One server per user: `claim_serving` takes the lock (a second server is refused), the testbed
starts, its state file says where its bus and tracker are, and the process waits for a signal.
Ctrl-C (SIGINT) and SIGTERM end the wait: the bus server closes every client's connection, the
drives and the tracker stop, and the state file is removed before the lock is released.

A testbed started for one command (auto_start.py) also watches a pipe from that command: the
kernel closes it when the command ends, however it ends (kill -9 included), and the end of the
pipe stops the testbed as SIGTERM does, so no testbed outlives the command that started it. A
byte on the pipe starts the fault clock in real time (in simulated time a frame on the bus does,
sim_backend.time_stamps): the command's --fault times count from its motion's start, as they do
with the testbed inside the command. A testbed served on its own has no such
command, and its fault times count from its start.

Where the machine lets it use two CPUs or more, the testbed runs on the last one, and the commands
that join it on the others (cpu_split.py). In real time its threads run under SCHED_FIFO at the
configuration's [sync] realtime_priority where the system grants it
(crest.driver.realtime_scheduling); the state file says what they got. Once serving, the objects
made to serve (drives, plant, bus server) are frozen out of the garbage collector (gc.freeze): a
full collection scans every tracked object it has not been told to skip, and the drives' replies
wait while it does (in the master such a collection took 10-46 ms; README, Control).
"""
from __future__ import annotations

import gc
import os
import signal
import threading
from collections.abc import Callable, Sequence
from pathlib import Path

from crest.backend import plant_summary, serve_virtual_testbed
from crest.config import TestbedConfig
from crest.driver.realtime_scheduling import realtime_threads
from crest.testbed_service.cpu_split import pin_process, testbed_cpus
from crest.testbed_service.state_file import ServedTestbed, claim_serving, config_digest, state_path


def serve_until_stopped(config: TestbedConfig, *, plant: str | None = None, plant_config: Path | None = None,
                        effects: dict | None = None, faults: Sequence[str] = (), port: int = 0,
                        on_ready: Callable[[ServedTestbed, Path], None] = lambda served, path: None,
                        parent_fd: int | None = None, simulated_time: bool = False) -> None:
    """Serve the virtual testbed of `config` until a signal's handler raises (KeyboardInterrupt
    for SIGINT, crest.driver.Terminated for SIGTERM); that exception propagates after the clean-up.
    on_ready(served, state file) is called once the state file is written. parent_fd: the read end
    of the starting command's pipe; a byte on it starts the fault clock, its end sends this process
    SIGTERM (see module doc). simulated_time: the testbed's clock moves only with the TIME stamps
    its master sends (sim_backend.time_stamps), not with the wall clock."""
    cpus = testbed_cpus()
    if cpus:
        pin_process(cpus)
    clock_requests = threading.Event()
    if parent_fd is not None:
        threading.Thread(target=_watch_parent, args=(parent_fd, clock_requests), name="parent-pipe",
                         daemon=True).start()
    priority = 0 if simulated_time else config.sync.realtime_priority
    with claim_serving() as publish, realtime_threads(priority) as scheduling:
        server = serve_virtual_testbed(config, plant=plant, plant_config=plant_config, effects=effects,
                                       faults=faults, faults_wait_for_run=parent_fd is not None, port=port,
                                       simulated_time=simulated_time)
        if parent_fd is not None:
            threading.Thread(target=_start_fault_clock_when_asked, args=(clock_requests, server.testbed),
                             name="fault-clock", daemon=True).start()
        try:
            served = ServedTestbed(pid=os.getpid(), bus_interface=server.bus_interface,
                                   bus_channel=server.bus_channel, tracker_port=server.tracker_port,
                                   config=str(Path(config.path).resolve()), config_digest=config_digest(config),
                                   simulated_time=simulated_time, cpus=cpus,
                                   scheduling=scheduling.describe(),
                                   plant=plant_summary(plant, plant_config, effects))
            publish(served)
            on_ready(served, state_path())
            gc.freeze()     # what serving needs for good: out of the collector's full passes (module doc)
            while True:
                signal.pause()
        finally:
            server.stop()


def _watch_parent(fd: int, clock_requests: threading.Event) -> None:
    """Read `fd` until its writer is gone, then SIGTERM this process; each byte read sets clock_requests."""
    with os.fdopen(fd, "rb", buffering=0) as pipe:
        while pipe.read(1):
            clock_requests.set()
    os.kill(os.getpid(), signal.SIGTERM)


def _start_fault_clock_when_asked(clock_requests: threading.Event, testbed) -> None:
    """Start the testbed's fault clock once the command asks (the first request counts)."""
    clock_requests.wait()
    testbed.start_fault_clock()
