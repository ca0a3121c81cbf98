"""Run the `crest` CLI as a user would: a separate process, its output and exit code."""
from __future__ import annotations

import os
import pty
import re
import select
import struct
import subprocess
import sys
import time
from pathlib import Path

import can

from crest.config import default_config_path
from crest.driver.cia402 import ENERGISED_STATES, QUICK_STOP, state_from_statusword

CREST = [sys.executable, "-m", "crest.cli.main"]
NODE_IDS = (1, 2, 3, 4, 5)          # configs/testbed.toml, tendon1..tendon4, insertion
REPO = Path(__file__).resolve().parents[2]


def crest(*args: str, timeout_s: float = 240.0, cwd: Path | None = None,
          env: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    """Run crest to the end; env adds to (or overrides) this process's environment."""
    env = dict(os.environ, PYTHONUNBUFFERED="1", **(env or {}))
    return subprocess.run([*CREST, *args], capture_output=True, text=True, timeout=timeout_s,
                          cwd=cwd or REPO, env=env)


def edited_config(folder: Path, **values) -> Path:
    """configs/testbed.toml with each `key = value` line given in `values` replaced (each key at the
    start of exactly one line), written as folder/testbed.toml beside a copy of its EDS."""
    text = default_config_path().read_text()
    for key, value in values.items():
        text, count = re.subn(rf"^{key} = \S+", f"{key} = {value}", text, flags=re.MULTILINE)
        assert count == 1, key
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "crest_drive.eds").write_text((default_config_path().parent / "crest_drive.eds").read_text())
    path = folder / "testbed.toml"
    path.write_text(text)
    return path


def record_short_run(folder: Path) -> Path:
    """A 3 s run of two set-points (one tendon pair pulled 1 mm), recorded by `crest run --fast` into
    folder/run.csv; returns the log's path."""
    setpoints, log = folder / "setpoints.csv", folder / "run.csv"
    setpoints.write_text("t,tendon_cmd_1,tendon_cmd_2,tendon_cmd_3,tendon_cmd_4,insertion_cmd\n"
                         "0,0,0,0,0,22\n3,1.0,0,-1.0,0,22\n")
    recorded = crest("run", str(setpoints), "--fast", "--record", str(log))
    assert recorded.returncode == 0, recorded.stderr
    return log


def start_crest(*args: str, cwd: Path | None = None, env: dict[str, str] | None = None,
                **kwargs) -> subprocess.Popen:
    env = dict(os.environ, PYTHONUNBUFFERED="1", **(env or {}))
    return subprocess.Popen([*CREST, *args], cwd=cwd or REPO, env=env, **kwargs)


def assert_every_drive_quick_stopped(blf_path: Path, silent_node: int | None = None) -> None:
    """The CAN recording beside a log: every drive got the quick stop, and its last answer shows it
    stopped (except the silent node's, a drive that no longer sends anything)."""
    frames = list(can.LogReader(blf_path))
    for node in NODE_IDS:
        controlwords = [struct.unpack("<Hi", bytes(f.data))[0] for f in frames if f.arbitration_id == 0x200 + node]
        statuswords = [struct.unpack("<Hih", bytes(f.data))[0] for f in frames if f.arbitration_id == 0x180 + node]
        assert QUICK_STOP in controlwords, f"node {node}"
        if node != silent_node:
            assert state_from_statusword(statuswords[-1]) not in ENERGISED_STATES, f"node {node}"


def read_until(fd, needle: bytes, timeout_s: float) -> bytes:
    """Read a pseudo-terminal `fd` until `needle` has appeared; returns all it read (fails after timeout_s)."""
    out = b""
    deadline = time.monotonic() + timeout_s
    while needle not in out:
        assert time.monotonic() < deadline, f"timed out waiting for {needle!r}; got {out[-400:]!r}"
        ready, _, _ = select.select([fd], [], [], 0.1)
        if ready:
            try:
                out += os.read(fd, 4096)
            except OSError:
                break
    return out


def on_a_terminal(command: list[str], env: dict[str, str] | None = None) -> tuple[int, subprocess.Popen]:
    """`command` with a pseudo-terminal as stdin, stdout and stderr: (the terminal's fd, process)."""
    master, slave = pty.openpty()
    env = dict(os.environ, TERM="xterm", PYTHONUNBUFFERED="1", **(env or {}))
    process = subprocess.Popen(command, cwd=REPO, env=env, stdin=slave, stdout=slave, stderr=slave, close_fds=True)
    os.close(slave)
    return master, process


def close_terminal(master: int, process: subprocess.Popen) -> None:
    """Close the terminal and kill the process if it still runs (a test that failed midway)."""
    os.close(master)
    if process.poll() is None:
        process.kill()
        process.wait()
