"""A served virtual testbed reached from other processes, as drives on a real bus are: status and
python-can's logger beside a run, estop from a second process, and kill -9 on either side.

Every run here is a real-time `crest run` in its own process on the served testbed's bus
(python-can interface "remote"); every other command is a process of its own as well.
"""
import json
import os
import re
import signal
import subprocess
import sys
import time
from urllib.parse import urlsplit

import can
import numpy as np
import pytest

from crest.exit_codes import ExitCode
from crest.log import read_log
from served_testbed import (HEARTBEAT_TIMEOUT_S, crest_lines, established_connections, rows_on_disk, start_run,
                            start_served_testbed, status_rows, stop, wait_for_rows)
from tests.cli.cli_runner import REPO, crest

AXES = ("tendon1", "tendon2", "tendon3", "tendon4", "insertion")
NODE_IDS = (1, 2, 3, 4, 5)
QUICK_STOP_SDO = bytes([0x2B, 0x40, 0x60, 0x00, 0x02, 0x00])   # expedited download: 0x6040:00 = 0x0002


@pytest.fixture
def served(tmp_path):
    """A testbed of the test's own: the plant keeps its state between commands, as a real catheter
    does (a run stopped mid-circle leaves it bent, and tendon homing adopts that as zero)."""
    served = start_served_testbed(tmp_path / "served")
    try:
        yield served
    finally:
        stop(served.process)


def test_status_and_the_can_logger_watch_a_run_from_other_processes_without_disturbing_it(served, tmp_path):
    log_path = tmp_path / "run.csv"
    run = start_run(served, log_path)
    # the recording run is one client of the bus: it records on its own connection, not a second one
    assert established_connections(urlsplit(served.state["bus_channel"]).port) == 1
    logger_out = tmp_path / "logger.txt"
    with logger_out.open("w") as sink:
        logger = subprocess.Popen([sys.executable, "-m", "can.logger", "-i", "remote", "-c", served.state["bus_channel"]],
                                  stdout=sink, stderr=subprocess.STDOUT, cwd=REPO)
    try:
        status = served.crest("status", "--config", str(served.config))
        assert status.returncode == ExitCode.OK, status.stderr
        rows = status_rows(status.stdout)
        assert list(rows) == list(AXES)
        for axis, fields in rows.items():       # the live states of the running drives, not reset ones
            assert fields[1:3] == ["OPERATIONAL", "OPERATION_ENABLED"], (axis, status.stdout)
        ids_seen = set()
        deadline = time.monotonic() + 120
        while not {0x80, *(0x180 + n for n in NODE_IDS), *(0x200 + n for n in NODE_IDS)} <= ids_seen:
            assert logger.poll() is None and time.monotonic() < deadline, logger_out.read_text()[-2000:]
            ids_seen = {int(found, 16) for found in re.findall(r"ID:\s+([0-9a-f]+)\s", logger_out.read_text())}
            time.sleep(0.2)
        # The run went on: still running, still writing rows; Ctrl-C, not the observers, ends it.
        wait_for_rows(log_path, rows_on_disk(log_path) + 20, run)
        run.send_signal(signal.SIGINT)
        _, stderr = run.communicate(timeout=120)
        assert run.returncode == ExitCode.INTERRUPTED, stderr
    finally:
        stop(run)
        logger.send_signal(signal.SIGINT)
        try:
            logger.wait(timeout=30)
        except subprocess.TimeoutExpired:
            logger.kill()
            logger.wait()


def test_estop_from_another_process_stops_every_axis_and_the_run_exits_with_its_stop_cause(served, tmp_path):
    log_path = tmp_path / "run.csv"
    run = start_run(served, log_path)
    try:
        estop = served.crest("estop", "--config", str(served.config))
        _, stderr = run.communicate(timeout=120)
    finally:
        stop(run)
    assert estop.returncode == ExitCode.OK, estop.stdout + estop.stderr
    assert [line.split()[:2] for line in estop.stdout.splitlines()] == [[axis, "stopped"] for axis in AXES]
    lines = crest_lines(stderr)
    assert run.returncode == ExitCode.ERROR, stderr
    assert len(lines) == 1 and "without a command from this host (crest estop" in lines[0], stderr
    summary = json.loads(log_path.with_suffix(".json").read_text())["summary"]
    assert summary["exit_code"] == ExitCode.ERROR and "crest estop" in summary["stop_cause"]
    # The run's CAN recording, made on its own connection to the served bus, holds the estop's
    # quick stop to tendon1, the first it stops: a frame another process sent. (The run stops
    # itself on that first stopped axis and closes its recording while estop goes on.)
    frames = list(can.LogReader(log_path.with_suffix(".blf")))
    assert any(f.arbitration_id == 0x601 and bytes(f.data[:6]) == QUICK_STOP_SDO for f in frames)


def test_kill_9_of_the_master_lets_every_served_drive_stop_on_the_lost_heartbeat(served, tmp_path):
    run = start_run(served, tmp_path / "run.csv")
    run.kill()
    run.communicate()
    deadline = time.monotonic() + 10 * HEARTBEAT_TIMEOUT_S + 120
    while True:
        status = served.crest("status", "--config", str(served.config))
        rows = status_rows(status.stdout)
        if list(rows) == list(AXES) and all(fields[2] == "FAULT" and fields[5] == "0x8130" for fields in rows.values()):
            break                                # 0x8130: heartbeat lost, the drive stopped hearing the host
        assert time.monotonic() < deadline, status.stdout + status.stderr
        time.sleep(1.0)


def test_kill_9_of_the_served_testbed_stops_the_run_on_every_axis_heartbeat_lost_with_its_log(tmp_path):
    served = start_served_testbed(tmp_path)
    log_path = tmp_path / "run.csv"
    run = None
    try:
        run = start_run(served, log_path)
        served.process.kill()                    # the drives, the plant and the tracker vanish at once
        served.process.communicate()
        _, stderr = run.communicate(timeout=120)
    finally:
        if run is not None:
            stop(run)
        stop(served.process)
    assert run.returncode == ExitCode.HEARTBEAT_LOST, stderr
    lines = crest_lines(stderr)
    assert len(lines) == 1 and "HEARTBEAT_LOST" in lines[0] and "Traceback" not in stderr, stderr
    named, _, reason = lines[0].partition(": no heartbeat from ")
    assert sorted(named.split("(HEARTBEAT_LOST): ")[1].split(", ")) == sorted(AXES), lines[0]
    assert reason.startswith("5 drives at once"), lines[0]
    summary = json.loads(log_path.with_suffix(".json").read_text())["summary"]
    assert summary["exit_code"] == ExitCode.HEARTBEAT_LOST and summary["stop_cause"] in lines[0]
    assert len(read_log(log_path)) >= 20


def test_a_configuration_whose_bus_and_tracker_name_the_served_testbed_runs_on_it_as_on_hardware(served, tmp_path):
    """[bus] names python-can's `remote` interface and the served bus, [tracker].port its pseudo-
    terminal: a command opens both as it opens a hardware bus and a serial tracker. Its runtime
    folder holds no state file, so the configuration alone takes it there."""
    text = served.config.read_text()
    for key, value in (("interface", "remote"), ("channel", served.state["bus_channel"]),
                       ("port", served.state["tracker_port"])):
        text, count = re.subn(rf'^{key} = "[^"]*"', f'{key} = "{value}"', text, count=1, flags=re.MULTILINE)
        assert count == 1, key
    hardware = tmp_path / "hardware"
    hardware.mkdir()
    (hardware / "crest_drive.eds").write_text((served.config.parent / "crest_drive.eds").read_text())
    (hardware / "testbed.toml").write_text(text)
    runtime = tmp_path / "no_state_file"
    runtime.mkdir(mode=0o700)
    log_path = tmp_path / "run.csv"
    move = crest("move", "--pitch", "30", "--yaw", "0", "--config", str(hardware / "testbed.toml"),
                 "--record", str(log_path), env={"XDG_RUNTIME_DIR": str(runtime)})
    assert move.returncode == ExitCode.OK, move.stderr
    assert served.process.poll() is None and not (runtime / "crest").exists()   # it joined, started nothing
    log = read_log(log_path)
    assert len(log) > 20 and np.isfinite(log.tip_mm).all(axis=1).sum() > 5      # tips from the served tracker
    # the CAN recording holds the host's own SYNCs and RPDOs as sent (a second handle on a hardware
    # bus would never see them) and the drives' TPDOs as received
    frames = list(can.LogReader(log_path.with_suffix(".blf")))
    assert {0x80, *(0x200 + n for n in NODE_IDS)} <= {f.arbitration_id for f in frames if not f.is_rx}
    assert {0x180 + n for n in NODE_IDS} <= {f.arbitration_id for f in frames if f.is_rx}


def thread_cpu_sets(pid: int) -> set[frozenset[int]]:
    """The CPU masks of every thread of process `pid`."""
    return {frozenset(os.sched_getaffinity(int(thread))) for thread in os.listdir(f"/proc/{pid}/task")}


@pytest.mark.skipif(len(os.sched_getaffinity(0)) < 2, reason="with one CPU nothing is pinned")
def test_the_served_testbed_and_a_run_joined_to_it_run_on_cpus_of_their_own(served, tmp_path):
    allowed = os.sched_getaffinity(0)
    testbed_cpus = frozenset(served.state["cpus"])
    assert testbed_cpus == {max(allowed)}
    assert thread_cpu_sets(served.state["pid"]) == {testbed_cpus}
    run = start_run(served, tmp_path / "run.csv")
    try:
        assert thread_cpu_sets(run.pid) == {frozenset(allowed - testbed_cpus)}
    finally:
        stop(run)
