"""The full stack on the virtual testbed: five drives, a controller and the tracker at a fast SYNC,
with the testbed in a process of its own (across a process boundary, as on a real bus) or in the
master's process.

Each set-up runs under the normal scheduler or with the threads of both processes under SCHED_FIFO
(the configuration's [sync] realtime_priority, crest.driver.realtime_scheduling); the result says
what each process got.

Measured by the master as it sends the SYNCs (crest.driver.sync_timing; a second client on the
bus would load the cycle it measures): the achieved rate, the period jitter (|period - nominal|,
p50/p99) and missed cycles (a period longer than 1.5 nominal periods), each counted by where its
time went: the cycle's thread woke late, or the cycle before it overran. From every frame the master
sends and receives (Backend.tapped): the bus load the traffic would put on a real bus. From the
run itself: the cycles in which a drive's answer did not come within the master's reply time
(crest.driver.sync_cycle: two periods, at least 20 ms, in real time; such a row lacks the answer),
which the goal counts as missed too; and how long the drives' answers took after each SYNC, as the master
saw them (crest.driver.answer_latency: p50, p99, p99.9, longest), where the cycle's time goes.
From the kernel: the time the hypervisor took from each CPU during the run (crest.bench.steal_time),
when every thread on that CPU stood still. With a profile folder, where each process of the run (the
master, the served testbed, the command process) spent its time: each thread's CPU and, from
py-spy's samples, where in the code each thread was (crest.bench.process_profile). The profiler
stops each process for a moment at every sample and shares the two CPUs with the stack, so a
profiled run's timing is not the goal's measurement.
"""
from __future__ import annotations

import os
import re
import shutil
import tempfile
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from control import Articulation, make_controller
from crest.bench.process_profile import ProcessTreeProfile
from crest.bench.steal_time import StealMeter
from crest.config import default_config_path, load_testbed_config
from crest.driver import SafetyStop
from crest.experiment.builtin_trajectories import BuiltinOptions, builtin_trajectory
from crest.experiment.controlled_run import commands_in_own_process, run_with_controller
from crest.experiment.workspace_from_config import limits_for, workspace_for
from crest.session import SessionOptions, open_session
from crest.testbed_service.auto_start import MODE_VARIABLE
from model import CatheterParams
from sim_backend.bus_load import BusLoadMeter

PROFILE_RATE_HZ = 100           # py-spy's samples per second of every thread
PROFILE_DELAY_S = 4.0           # the profile starts once the run and its command process are going
PROFILE_END_S = 8.0             # and ends this long before the run's nominal end


def full_stack(sync_rate_hz: float = 500.0, duration_s: float = 60.0, controller_name: str = "dahl",
               testbed_process: bool = True, realtime_priority: int = 0, profile_folder: Path | None = None) -> dict:
    """The dahl circle at `sync_rate_hz`, with the virtual testbed in a process of its own (the master
    reaches its drives over the served bus, as it reaches drives on a real bus) or in this one.

    The served testbed runs the configuration file of this rate and priority (configs/testbed.toml
    with the SYNC period and realtime_priority changed, written to a temporary folder): a testbed
    process reads its configuration from a file. A run that a safety stop ends (a heartbeat lost
    when the processes cannot keep up) is measured up to the stop and reported with its cause.
    profile_folder: where py-spy writes the raw stacks of each process of the run; the result then
    has "profile" (ProcessTreeProfile.finish, each process with its "role").
    """
    with tempfile.TemporaryDirectory(prefix="crest-stack-") as folder:
        config = load_testbed_config(_config_at_rate(Path(folder), sync_rate_hz, realtime_priority))
        with _testbed_mode("process" if testbed_process else "in-process"):
            result = _measure(config, sync_rate_hz, duration_s, controller_name, profile_folder)
    return {**result, "testbed": "its own process" if testbed_process else "this process"}


def _config_at_rate(folder: Path, sync_rate_hz: float, realtime_priority: int) -> Path:
    """configs/testbed.toml (with its drive EDS) in `folder`, its SYNC period set to 1/sync_rate_hz
    and its threads' real-time priority to `realtime_priority`."""
    source = default_config_path()
    text = source.read_text()
    for key, value in (("period_s", 1.0 / sync_rate_hz), ("realtime_priority", realtime_priority)):
        text, count = re.subn(rf"^{key} = \S+", f"{key} = {value!r}", text, flags=re.MULTILINE)
        if count != 1:
            raise ValueError(f"{source}: expected one [sync] {key} line, found {count}")
    shutil.copy(source.parent / "crest_drive.eds", folder / "crest_drive.eds")
    path = folder / "testbed.toml"
    path.write_text(text)
    return path


@contextmanager
def _testbed_mode(mode: str) -> Iterator[None]:
    """CREST_VIRTUAL_TESTBED for the session opened inside (see crest.testbed_service.auto_start)."""
    before = os.environ.get(MODE_VARIABLE)
    os.environ[MODE_VARIABLE] = mode
    try:
        yield
    finally:
        if before is None:
            del os.environ[MODE_VARIABLE]
        else:
            os.environ[MODE_VARIABLE] = before


def _measure(config, sync_rate_hz: float, duration_s: float, controller_name: str,
             profile_folder: Path | None) -> dict:
    params = CatheterParams.from_toml()
    workspace, limits = workspace_for(config, params), limits_for(config)
    period_s = config.sync.period_s
    start = Articulation(0.0, 0.0, config.insertion_axis.home_position_mm)
    circle_period_s = 8.0
    turns = max(1.0, (duration_s - 8.0) / circle_period_s)
    trajectory = builtin_trajectory("circle", workspace, limits,
                                    BuiltinOptions(articulation_deg=90.0, periods=turns,
                                                   circle_period_s=circle_period_s), period_s, start)
    controller = make_controller(controller_name, workspace, limits, period_s)
    stopped, rms_tip_error_mm, held_cycles, unanswered_cycles = None, None, None, None
    with open_session(SessionOptions(config=config)) as session:
        session.testbed.home()
        # into cyclic synchronous position before the timing starts: the change of operation mode is
        # an SDO exchange between two SYNCs, not a cycle of the control loop
        session.testbed.cycle(session.testbed.positions())
        meter = BusLoadMeter(config.bus.bitrate, period_s)      # what the frames on the wire take
        session.testbed.answer_latency.reset()
        session.testbed.sync_timing.reset()
        steal = StealMeter()
        steal.start()
        profile = ProcessTreeProfile(os.getpid(), profile_folder, PROFILE_RATE_HZ) if profile_folder else None
        profile_s = max(1.0, duration_s - PROFILE_DELAY_S - PROFILE_END_S)
        starter = threading.Timer(PROFILE_DELAY_S, profile.start, args=(profile_s,)) if profile else None
        if starter is not None:
            starter.start()
        with session.backend.tapped(meter):
            try:
                result = run_with_controller(session, trajectory, controller)
                rms_tip_error_mm, held_cycles = result.rms_tip_error_mm, result.held_cycles
                unanswered_cycles = result.unanswered_cycles
            except SafetyStop as stop:
                stopped = str(stop)
            timing = session.testbed.sync_timing.summary()
        stolen = steal.stop()
        profiled = None
        if starter is not None:
            starter.cancel()           # a run that stopped before its profile began has none
            starter.join()
            profiled = [{**row, "role": _role(row)} for row in profile.finish(timeout_s=duration_s)]
        load = meter.report()
        answers = session.testbed.answer_latency.summary()
        plant_rate_hz = session.backend.virtual.plant_rate_hz if session.backend.virtual is not None else None
        master_scheduling = session.scheduling.describe()
        command_process = commands_in_own_process(session, controller)
        testbed_scheduling = (session.backend.served.scheduling if session.backend.served is not None
                              else master_scheduling)
    return {"sync_rate_hz_nominal": sync_rate_hz, "duration_s": timing["span_s"],
            "controller": controller_name, "cycles": timing["periods"],
            "achieved_rate_hz": timing["achieved_rate_hz"], "jitter_p50_ms": timing["jitter_p50_ms"],
            "jitter_p99_ms": timing["jitter_p99_ms"], "missed_cycles": timing["missed_cycles"],
            "missed_woke_late": timing["missed_woke_late"], "missed_overran": timing["missed_overran"],
            "longest_period_ms": timing["longest_period_ms"],
            "bus_load_mean": float(load.mean_load), "bus_load_max": float(load.max_load),
            "bus_bitrate_bit_s": int(load.bitrate_bit_s), "cycles_over_bus_capacity": len(load.overloaded),
            "rms_tip_error_mm": rms_tip_error_mm, "plant_rate_hz": plant_rate_hz, "stopped": stopped,
            "realtime_priority": config.sync.realtime_priority, "master_scheduling": master_scheduling,
            "testbed_scheduling": testbed_scheduling, "commands_in_own_process": command_process,
            "cycles_held_for_a_command": held_cycles, "cycles_without_every_answer": unanswered_cycles,
            "answer_latency": answers, "hypervisor": stolen,
            "goal": "500 Hz with no missed cycle and p99 jitter <= 1 ms",
            **({"profile": profiled, "profile_seconds": profile.duration_s, "profile_rate_hz": PROFILE_RATE_HZ}
               if profiled is not None else {})}


def _role(row: dict) -> str:
    """Which process of the run a profiled process is, from its pid and command line."""
    if row["pid"] == os.getpid():
        return "master"
    if "testbed serve" in row["command"]:
        return "testbed"
    if "command_worker" in row["command"]:
        return "command process"
    return "other"
