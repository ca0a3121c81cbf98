"""The commands of an open-loop controller, computed ahead in a process of its own.

A controller that ignores what was measured (`uses_feedback` False: `cc`, `dahl`) gives the same
command for a set-point whenever it is asked, as long as it is asked in order. Its commands can
then be computed ahead of the cycle that sends them. In the master's own process that work holds
the interpreter lock that the SYNC cycle, the receive thread and the tracker need: at 500 Hz the
dahl inversion takes about half of the 2 ms period on the median, and in its tail more than the
rest of it (README, "Full stack across the process boundary"). In a process of its own it runs on
whichever CPU is free, and the master only takes the finished commands.

The worker (crest.experiment.command_worker) is a fresh interpreter (``python -m``; it never
re-runs the user's script, as multiprocessing's spawn would). It reads the controller, then batches
of set-points, from its stdin, and writes batches of commands to its stdout, all pickled. The
master sends the set-points in order, `lead` at most not yet answered, and a thread of its own
collects the commands, so neither side ever blocks on the other's pipe. An error in a command (a
set-point outside the workspace) comes back in its place and is raised by `next_command` at that
set-point, where it would have been raised in the master. The worker is started under the normal
scheduler even when the master is real-time, so a real-time master always runs first. `close` kills it; it exits by itself when its stdin
closes, so it does not outlive a master killed with kill -9.
"""
from __future__ import annotations

import os
import pickle
import queue
import subprocess
import sys
import threading
import time
from collections import deque
from collections.abc import Iterator, Sequence
from contextlib import contextmanager

from control import Controller, SetPoint, TendonCommand

START_TIMEOUT_S = 120.0     # the first command: a fresh interpreter imports numpy and the model
REPLY_TIMEOUT_S = 10.0      # after an answer, the next: the worker answers in milliseconds unless it is gone
WORKER_MODULE = "crest.experiment.command_worker"


@contextmanager
def _calling_thread_under_normal_scheduler() -> Iterator[None]:
    """The calling thread under SCHED_OTHER until the block ends, then back to its policy.

    A process started from a SCHED_FIFO thread inherits its policy. The worker would then run its
    interpreter's start (some 40 ms) ahead of the master on the master's CPU, and at 500 Hz some
    twenty SYNCs would not be sent. The collector thread, on the other hand, keeps the master's
    policy: it holds the master's interpreter lock while it unpickles a batch, and under the normal
    scheduler the busy worker could preempt it there and keep the cycle waiting for the lock."""
    if not hasattr(os, "sched_getscheduler") or os.sched_getscheduler(0) == os.SCHED_OTHER:
        yield
        return
    policy, param = os.sched_getscheduler(0), os.sched_getparam(0)
    os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))
    try:
        yield
    finally:
        os.sched_setscheduler(0, policy, param)


class CommandProcessError(RuntimeError):
    """The command process died or stopped answering."""


class CommandProcess:
    """`submit` the set-points in order, take `next_command` for each in the same order; `close` at the end.

    The worker's copy of `controller` is reset to `insertion_mm` before its first command; its
    commands come back `batch` at a time."""

    def __init__(self, controller: Controller, insertion_mm: float, *, lead: int = 128, batch: int = 8):
        if controller.uses_feedback:
            raise ValueError(f"controller {controller.name!r} uses feedback; its commands cannot be computed ahead")
        self.lead = int(lead)
        self._ready: deque[TendonCommand | Exception] = deque()
        self._submitted = 0
        self._taken = 0
        self._batches: queue.Queue[list | None] = queue.Queue()
        self._patience_s = START_TIMEOUT_S
        self._deadline_s = time.monotonic() + START_TIMEOUT_S
        with _calling_thread_under_normal_scheduler():
            self._process = subprocess.Popen([sys.executable, "-m", WORKER_MODULE], stdin=subprocess.PIPE,
                                             stdout=subprocess.PIPE)
        self._collector = threading.Thread(target=self._collect, name="crest-commands-in", daemon=True)
        self._collector.start()
        self._send((controller, float(insertion_mm), int(batch)))

    @property
    def pid(self) -> int:
        return self._process.pid

    @property
    def room(self) -> int:
        """How many more set-points `submit` takes now (at most `lead` unanswered)."""
        return self.lead - (self._submitted - self._taken)

    def submit(self, setpoints: Sequence[SetPoint]) -> None:
        """Send `setpoints` to the worker (a worker that owed nothing has its patience restart)."""
        if setpoints:
            if self._submitted - self._taken - len(self._ready) == 0:
                self._deadline_s = time.monotonic() + self._patience_s
            self._send(list(setpoints))
            self._submitted += len(setpoints)

    def ready(self) -> int:
        """How many commands are back and not yet taken, without waiting (an error counts as one; after
        it the worker answers nothing more, see `stopped_at_error`). CommandProcessError if the worker
        is gone, or owes answers and has been silent for longer than START_TIMEOUT_S after its start
        or REPLY_TIMEOUT_S after its last answer."""
        while True:
            try:
                self._extend(self._batches.get_nowait())
            except queue.Empty:
                break
        owed = self._submitted - self._taken - len(self._ready)
        if owed and not self.stopped_at_error and time.monotonic() > self._deadline_s:
            raise CommandProcessError("the controller's command process did not answer "
                                      f"within {self._patience_s:g} s")
        return len(self._ready)

    @property
    def stopped_at_error(self) -> bool:
        """The last answer back is an error: the worker will answer nothing after it."""
        return bool(self._ready) and isinstance(self._ready[-1], Exception)

    def next_command(self) -> TendonCommand:
        """The command for the next set-point submitted (waiting for it as `ready` allows); raises what
        computing it raised, or CommandProcessError when the worker is gone or silent."""
        if self._taken >= self._submitted:
            raise ValueError("next_command: every submitted set-point has had its command")
        if not self._ready:
            try:
                self._extend(self._batches.get(timeout=max(0.0, self._deadline_s - time.monotonic())))
            except queue.Empty:
                raise CommandProcessError("the controller's command process did not answer "
                                          f"within {self._patience_s:g} s") from None
        self._taken += 1
        command = self._ready.popleft()
        if isinstance(command, Exception):
            raise command
        return command

    def close(self) -> None:
        """End the worker at once (SIGKILL: it holds nothing but commands no one will take, and a
        graceful interpreter exit would take longer than the drives wait for the next cycle)."""
        self._process.kill()
        self._process.wait()
        self._collector.join()
        for pipe in (self._process.stdin, self._process.stdout):
            try:
                pipe.close()
            except OSError:
                pass    # a write the dead worker never read

    def _send(self, message) -> None:
        try:
            pickle.dump(message, self._process.stdin, protocol=pickle.HIGHEST_PROTOCOL)
            self._process.stdin.flush()
        except OSError:
            raise CommandProcessError(f"the controller's command process exited (exit code "
                                      f"{self._process.poll()})") from None

    def _collect(self) -> None:
        """The collector thread: every batch the worker writes, into the queue; None at its end."""
        try:
            while True:
                self._batches.put(pickle.load(self._process.stdout))
        except (EOFError, OSError, pickle.UnpicklingError):
            self._batches.put(None)

    def _extend(self, batch: list | None) -> None:
        """A batch from the collector into the ready commands (the worker's patience restarts);
        None (the worker's end) raises."""
        if batch is None:
            self._batches.put(None)     # every later call says the same
            raise CommandProcessError(f"the controller's command process exited (exit code "
                                      f"{self._process.wait()})")
        self._ready.extend(batch)
        self._patience_s = REPLY_TIMEOUT_S
        self._deadline_s = time.monotonic() + REPLY_TIMEOUT_S
