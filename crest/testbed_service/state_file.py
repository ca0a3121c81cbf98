"""Where a served virtual testbed is: a small JSON state file, and a lock its server holds.

`crest testbed serve` holds an exclusive lock (flock) on ``testbed.lock`` for its whole life and
writes ``testbed.json`` beside it::

    {"pid": 4242, "bus_interface": "remote", "bus_channel": "ws://127.0.0.1:40123/",
     "tracker_port": "/dev/pts/7", "config": "/path/to/testbed.toml", "config_digest": "9f2c...",
     "simulated_time": false, "cpus": [1], "scheduling": "normal scheduler"}

``config_digest`` is `config_digest(config)` of the configuration the testbed was built from: a
command joins only a testbed built from the configuration it runs with, to the last value.
``simulated_time`` is true for a testbed whose clock moves only with its master's TIME stamps
(`crest testbed serve --simulated-time`, sim_backend.time_stamps): only a command in simulated time
(`--fast`) can drive it. ``cpus`` are the CPUs the testbed runs on (crest.testbed_service.cpu_split;
empty when it is not pinned): a command that joins it runs on the others. ``scheduling`` is what
its threads run under (crest.driver.realtime_scheduling: real-time, or the normal scheduler and why).

The kernel releases the lock when the server ends, however it ends (kill -9 included). A state
file whose lock nobody holds is therefore stale, left by a killed server: the other commands
ignore it, and the next server replaces it.

The folder is ``$XDG_RUNTIME_DIR/crest``, or ``<temp dir>/crest-<uid>`` where that is unset.
"""
from __future__ import annotations

import fcntl
import hashlib
import json
import os
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import asdict, dataclass
from pathlib import Path

STATE_NAME = "testbed.json"
LOCK_NAME = "testbed.lock"
CLAIM_RETRY_S = 1.0     # a command looking at the lock holds it for an instant; a new server waits that out


@dataclass(frozen=True)
class ServedTestbed:
    """A running served testbed: its process, its CAN bus (python-can interface and channel), its
    tracker's serial port, the testbed configuration it serves and the plant behind its drives (one
    line, `crest.backend.plant_summary`; empty in the state of a testbed served by an older crest)."""

    pid: int
    bus_interface: str
    bus_channel: str
    tracker_port: str
    config: str
    config_digest: str
    simulated_time: bool = False
    cpus: tuple[int, ...] = ()
    scheduling: str = "normal scheduler"
    plant: str = ""

    def describe(self) -> str:
        return (f"pid {self.pid}, CAN bus interface '{self.bus_interface}' channel '{self.bus_channel}', "
                f"tracker {self.tracker_port}" + (", in simulated time" if self.simulated_time else ""))


class TestbedAlreadyServed(RuntimeError):
    """A second server was asked for while one runs (the message names it and how to stop it)."""

    __test__ = False  # not a pytest test class despite the name


def config_digest(config) -> str:
    """SHA-256 (hex) of a TestbedConfig's values: its `as_dict()` with keys sorted, without the
    file's own path, and with the EDS paths resolved (a file named two ways is the same file)."""
    values = config.as_dict()
    del values["path"]
    for axis in values["axes"]:
        axis["eds_path"] = str(Path(axis["eds_path"]).resolve())
    return hashlib.sha256(json.dumps(values, sort_keys=True).encode()).hexdigest()


def state_dir() -> Path:
    runtime = os.environ.get("XDG_RUNTIME_DIR")
    return Path(runtime) / "crest" if runtime else Path(tempfile.gettempdir()) / f"crest-{os.getuid()}"


def state_path() -> Path:
    return state_dir() / STATE_NAME


def running_testbed() -> ServedTestbed | None:
    """The served testbed that is running now, or None (no state file, or a stale one)."""
    folder = state_dir()
    try:
        lock_fd = os.open(folder / LOCK_NAME, os.O_RDONLY)
    except FileNotFoundError:
        return None
    try:
        try:
            fcntl.flock(lock_fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except BlockingIOError:
            return _read_state(folder / STATE_NAME)     # the server holds the lock: it runs
        fcntl.flock(lock_fd, fcntl.LOCK_UN)
        return None                                     # nobody holds it: any state file is stale
    finally:
        os.close(lock_fd)


@contextmanager
def claim_serving() -> Iterator[Callable[[ServedTestbed], None]]:
    """Become the one server: take the lock, or raise TestbedAlreadyServed naming the running one.

    Yields ``publish(ServedTestbed)``, which writes the state file (atomically). On leaving, the
    state file is removed and then the lock released.
    """
    folder = state_dir()
    folder.mkdir(mode=0o700, parents=True, exist_ok=True)
    lock_fd = os.open(folder / LOCK_NAME, os.O_RDWR | os.O_CREAT, 0o600)
    try:
        _lock_exclusively(lock_fd, folder)
        state = folder / STATE_NAME
        state.unlink(missing_ok=True)       # a stale one from a killed server

        def publish(served: ServedTestbed) -> None:
            partial = state.with_suffix(".json.partial")
            partial.write_text(json.dumps(asdict(served), indent=1) + "\n")
            partial.replace(state)

        try:
            yield publish
        finally:
            state.unlink(missing_ok=True)
    finally:
        os.close(lock_fd)       # releases the lock


def _lock_exclusively(lock_fd: int, folder: Path) -> None:
    deadline_s = time.monotonic() + CLAIM_RETRY_S
    while True:
        try:
            fcntl.flock(lock_fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return
        except BlockingIOError:
            if time.monotonic() > deadline_s:
                break
            time.sleep(0.05)
    running = _read_state(folder / STATE_NAME)
    where = running.describe() if running is not None else f"its state file {folder / STATE_NAME} is not written yet"
    raise TestbedAlreadyServed(f"a served virtual testbed is already running ({where}); "
                               "stop it first (Ctrl-C in its terminal, or kill -TERM its pid)")


def _read_state(path: Path) -> ServedTestbed | None:
    try:
        return ServedTestbed(**json.loads(path.read_text()))
    except FileNotFoundError:
        return None     # the server is starting (lock taken, state not yet written) or stopping
    except (json.JSONDecodeError, TypeError) as exc:
        raise RuntimeError(f"{path}: unreadable state of a running served testbed ({exc}); "
                           "stop that testbed (its pid holds the lock beside this file) and start it again") from exc
