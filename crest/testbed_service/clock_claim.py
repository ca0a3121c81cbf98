"""Who drives a served testbed's simulated clock: one command at a time.

A testbed served in simulated time moves with the TIME stamps of the command that drives it
(sim_backend.time_stamps); two commands stamping it would move one clock back and forth. The
command that drives it holds an exclusive lock (flock) on ``clock.lock`` beside the state file from
before it starts or joins that testbed until it closes its backend; the kernel releases the lock
when the command ends, however it ends. A second command in simulated time that finds the lock
taken keeps its testbed inside its own process (crest.backend).
"""
from __future__ import annotations

import fcntl
import os

from crest.testbed_service.state_file import state_dir

CLOCK_LOCK_NAME = "clock.lock"


def claim_clock() -> int | None:
    """The file descriptor that holds the clock lock (close it to release), or None when another
    command holds it."""
    folder = state_dir()
    folder.mkdir(mode=0o700, parents=True, exist_ok=True)
    lock_fd = os.open(folder / CLOCK_LOCK_NAME, os.O_RDWR | os.O_CREAT, 0o600)
    try:
        fcntl.flock(lock_fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        os.close(lock_fd)
        return None
    return lock_fd
