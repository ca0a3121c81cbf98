"""A served virtual testbed (`crest testbed serve`) in a process of its own, for the tests.

Every process here is started as a user starts it and is stopped by the test that started it.
The state file lives in a folder of the test's own ($XDG_RUNTIME_DIR), so a testbed a developer
is serving is neither joined nor disturbed.

The configuration is configs/testbed.toml with heartbeats a loaded 2-core machine cannot miss by
accident: real time cannot be simulated across processes, and a starved process must not trip a
heartbeat loss the test did not cause (the heartbeat tests cause theirs with kill -9).
"""
from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from tests.cli.cli_runner import crest, edited_config, start_crest

START_TIMEOUT_S = 300.0     # the first start in a fresh checkout compiles the plant's kernels
STOP_TIMEOUT_S = 60.0
GONE_TIMEOUT_S = 120.0      # a command's own testbed process ends this long after the command at most
HEARTBEAT_TIMEOUT_S = 2.0
RELAXED_TIMING = {         # [master] key: value
    "heartbeat_period_s": 0.2,
    "drive_heartbeat_period_s": 0.2,
    "heartbeat_timeout_s": HEARTBEAT_TIMEOUT_S,
    "sdo_timeout_s": 2.0,
}


def relaxed_config(folder: Path, **changes) -> Path:
    """configs/testbed.toml with RELAXED_TIMING and `changes` (further key = value lines),
    written into `folder` with its EDS."""
    return edited_config(folder, **{**RELAXED_TIMING, **changes})


@dataclass
class ServedTestbed:
    process: subprocess.Popen
    config: Path
    env: dict[str, str]          # what every crest process of the test runs with
    state_file: Path

    @property
    def state(self) -> dict:
        return json.loads(self.state_file.read_text())

    def crest(self, *args: str, timeout_s: float = 240.0) -> subprocess.CompletedProcess:
        return crest(*args, timeout_s=timeout_s, env=self.env)

    def start_crest(self, *args: str, **kwargs) -> subprocess.Popen:
        return start_crest(*args, env=self.env, **kwargs)


def start_served_testbed(tmp_path: Path, config: Path | None = None, *options: str, **popen) -> ServedTestbed:
    """`crest testbed serve [options]`, returned once its state file is written (the caller stops it);
    `popen`: further arguments of subprocess.Popen."""
    env = {"XDG_RUNTIME_DIR": str(tmp_path / "runtime")}
    config = config or relaxed_config(tmp_path / "config")
    state_file = tmp_path / "runtime" / "crest" / "testbed.json"
    process = start_crest("testbed", "serve", "--config", str(config), *options, env=env,
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **popen)
    served = ServedTestbed(process, config, env, state_file)
    deadline = time.monotonic() + START_TIMEOUT_S
    while not (state_file.exists() and _state_pid(state_file) == process.pid):
        if process.poll() is not None or time.monotonic() > deadline:
            stop(process)
            raise AssertionError(f"crest testbed serve did not start: {process.communicate()}")
        time.sleep(0.1)
    return served


def _state_pid(state_file: Path) -> int | None:
    try:
        return json.loads(state_file.read_text())["pid"]
    except (FileNotFoundError, json.JSONDecodeError):
        return None     # not yet written (it is replaced whole, but may vanish between the two calls)


def stop(process: subprocess.Popen) -> None:
    """SIGTERM, then SIGKILL if it does not end; the process's output stays readable."""
    if process.poll() is None:
        process.send_signal(signal.SIGTERM)
        try:
            process.wait(timeout=STOP_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


def wait_gone(pid: int, state_file: Path) -> None:
    """Wait until the testbed process `pid` has ended and its state file is gone (fails after GONE_TIMEOUT_S)."""
    deadline = time.monotonic() + GONE_TIMEOUT_S
    while process_alive(pid) or state_file.exists():
        assert time.monotonic() < deadline, f"testbed process {pid} or {state_file} outlived its command"
        time.sleep(0.2)


def established_connections(port: int) -> int:
    """TCP connections on 127.0.0.1 whose server side is `port` (the kernel's table, /proc/net/tcp)."""
    count = 0
    for line in open("/proc/net/tcp").read().splitlines()[1:]:
        local, state = line.split()[1], line.split()[3]
        count += int(local.split(":")[1], 16) == port and state == "01"
    return count


def rows_on_disk(log_path: Path) -> int:
    return log_path.read_bytes().count(b"\n") - 1 if log_path.exists() else 0


def wait_for_rows(log_path: Path, rows: int, process: subprocess.Popen, timeout_s: float = 300.0) -> None:
    deadline = time.monotonic() + timeout_s
    while rows_on_disk(log_path) < rows:
        assert process.poll() is None, f"the run ended early: {process.communicate()}"
        assert time.monotonic() < deadline, f"fewer than {rows} rows in {log_path} after {timeout_s} s"
        time.sleep(0.1)


def start_run(served: ServedTestbed, log_path: Path) -> subprocess.Popen:
    """A long real-time `crest run builtin:circle --record LOG` on the served testbed (see start_circle)."""
    return start_circle(served.start_crest, log_path, "--config", str(served.config))


def start_circle(start: Callable[..., subprocess.Popen], log_path: Path, *options: str) -> subprocess.Popen:
    """A long `crest run builtin:circle --record LOG [options]`, started by `start` (start_crest with
    its environment), returned once its trajectory writes rows. The free length of 25 mm keeps the
    move to the start short."""
    run = start("run", "builtin:circle", "--insertion-mm", "25", "--periods", "100", "--record", str(log_path),
                *options, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        wait_for_rows(log_path, 20, run)
    except BaseException:
        stop(run)
        raise
    return run


def crest_lines(stderr: str) -> list[str]:
    return [line for line in stderr.splitlines() if line.startswith("crest")]


def status_rows(stdout: str) -> dict[str, list[str]]:
    """`crest status`'s table: {axis: [node, NMT, CiA 402 state, position, following error, fault...]}."""
    rows = {}
    for line in stdout.splitlines():
        fields = line.split()
        if fields and re.fullmatch(r"tendon[1-4]|insertion", fields[0]):
            rows[fields[0]] = fields[1:]
    return rows


def process_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True
