"""A served virtual testbed started for one command and stopped with it.

A command that finds no served testbed starts `crest testbed serve` as its child (with
`--simulated-time` for a command in simulated time, `--fast`), joins it like any served testbed
(so `crest estop` and `crest status` reach it from other processes), and stops it when the
command ends. The child holds the read end of a pipe whose only writer is
the command: when the command ends, however it ends (a crash, kill -9), the kernel closes the
pipe and the child stops itself (serve.py). In real time the same pipe carries the command's one
message to its testbed: a byte that starts the fault clock of its `--fault`s
(`OwnedTestbed.start_fault_clock`); in simulated time a frame on the bus does, in order with the
TIME stamps (sim_backend.time_stamps).

With ``CREST_VIRTUAL_TESTBED=in-process`` in the environment, a command boots the virtual testbed
inside its own process instead, on python-can's in-process bus (faster to start, reachable by
no other process); ``process`` is the default.
"""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from crest.testbed_service.state_file import ServedTestbed, running_testbed

MODE_VARIABLE = "CREST_VIRTUAL_TESTBED"
MODES = ("in-process", "process")
START_TIMEOUT_S = 300.0     # a first start in a fresh install compiles the plant's kernels
STOP_TIMEOUT_S = 30.0
FAULT_CLOCK_BYTE = b"F"     # written on the pipe: start the fault clock


class AutoStartError(RuntimeError):
    """The testbed process could not be started (the message holds its own last words)."""


def wants_own_process() -> bool:
    """False when CREST_VIRTUAL_TESTBED asks for the virtual testbed inside the command's process."""
    mode = os.environ.get(MODE_VARIABLE, "process")
    if mode not in MODES:
        raise ValueError(f"{MODE_VARIABLE}={mode!r}: expected one of {', '.join(MODES)}")
    return mode == "process"


@dataclass
class OwnedTestbed:
    """The testbed process a command started, and the command's end of the pipe it watches."""

    process: subprocess.Popen
    pipe_fd: int
    served: ServedTestbed

    def start_fault_clock(self) -> None:
        """The testbed's --fault times count from now (the first call counts; see serve.py)."""
        if self.pipe_fd >= 0:
            os.write(self.pipe_fd, FAULT_CLOCK_BYTE)

    def stop(self) -> None:
        """Close the pipe (the testbed stops itself) and wait for the process; kill it if it hangs."""
        if self.pipe_fd >= 0:
            os.close(self.pipe_fd)
            self.pipe_fd = -1
        try:
            self.process.wait(timeout=STOP_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


def start_owned_testbed(config_path: Path, plant: str | None, plant_config: Path | None, effects: dict,
                        faults: Sequence[str], simulated_time: bool = False) -> OwnedTestbed:
    """`crest testbed serve` as a child of this process, returned once it serves (AutoStartError if
    it cannot start, e.g. because another testbed took the lock in the meantime). plant, plant_config,
    effects and faults as for `crest.backend.open_backend`; the faults' clock starts with
    `OwnedTestbed.start_fault_clock`. simulated_time: its clock moves with this command's TIME stamps."""
    read_fd, write_fd = os.pipe()
    os.set_inheritable(read_fd, True)
    command = [sys.executable, "-m", "crest.cli.main", "testbed", "serve", "--config", str(config_path),
               "--parent-fd", str(read_fd)]
    if simulated_time:
        command += ["--simulated-time"]
    if plant is not None:
        command += ["--plant", plant]
    if plant_config is not None:
        command += ["--plant-config", str(plant_config)]
    for fault in faults:
        command += ["--fault", fault]
    for effect_id, values in effects.items():
        command += ["--effect", effect_id + (":" + ",".join(f"{name}={value!r}" for name, value in values.items())
                                             if values else "")]
    with tempfile.TemporaryFile("w+") as output:
        try:
            process = subprocess.Popen(command, pass_fds=(read_fd,), stdin=subprocess.DEVNULL,
                                       stdout=subprocess.DEVNULL, stderr=output, start_new_session=True)
        finally:
            os.close(read_fd)
        owned = OwnedTestbed(process, write_fd, None)
        deadline_s = time.monotonic() + START_TIMEOUT_S
        relayed = 0     # bytes of the testbed's output looked at so far
        while True:
            relayed = _relay_notices(output.fileno(), relayed)
            served = running_testbed()
            if served is not None and served.pid == process.pid:
                owned.served = served
                return owned
            if process.poll() is not None or time.monotonic() > deadline_s:
                owned.stop()
                output.seek(0)
                last_words = " | ".join(output.read().strip().splitlines()[-3:])
                raise AutoStartError(f"the virtual testbed's own process did not start ({last_words or 'no output'}); "
                                     f"set {MODE_VARIABLE}=in-process to run it inside this command")
            time.sleep(0.1)


def _relay_notices(fd: int, start: int) -> int:
    """Pass on the starting testbed's notices (its complete stderr lines 'crest: ...' from byte
    `start` of the file `fd`, errors excepted; e.g. that its plant's kernel is compiling) to this
    command's stderr. Returns where the first incomplete line starts. The testbed writes through
    the same file offset, so this reads with pread and leaves the offset alone."""
    text = os.pread(fd, 1 << 16, start)
    complete = text[:text.rfind(b"\n") + 1]
    for line in complete.decode(errors="replace").splitlines():
        if line.startswith("crest: ") and not line.startswith("crest: error"):
            print(line, file=sys.stderr, flush=True)
    return start + len(complete)
