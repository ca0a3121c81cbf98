"""Ctrl-C and SIGTERM: the command stops and reports; processes it forked end quietly.

A shell starts background commands with SIGINT ignored, and Python then never raises
KeyboardInterrupt. An interrupt (Ctrl-C, or `kill -INT` from a supervisor) must still stop every
axis and save the log, however crest was started, so SIGINT always raises KeyboardInterrupt.
SIGTERM (`kill PID`, a service manager) takes the same path with its own exception, Terminated;
later SIGTERMs are ignored, so a supervisor that repeats the signal cannot break off the stop the
first one started (SIGKILL still ends the process). While a session holds the testbed the
exception is not raised where the signal finds the main thread but at the cycle's next safe point
(crest.driver.stop_requests): raised inside a library's locking code it can leave a lock held and
hang the stop itself.

Processes the command forks (the fits' process pool) inherit these handlers. Ctrl-C in a terminal
and a service manager's stop signal the whole process group, and an exception in such a worker
prints a traceback from inside the pool's machinery. There the handler ends the worker by the
signal's default action instead: the command itself stops, ends its pool and prints the one line.
"""
from __future__ import annotations

import os
import signal

from crest.driver import Terminated, stop_requests


def install_stop_signals() -> None:
    """Route SIGINT to KeyboardInterrupt and SIGTERM to Terminated in this process (see module doc)."""
    command_pid = os.getpid()

    def interrupt(signum, frame) -> None:
        if os.getpid() != command_pid:
            _end_quietly(signum)
        error = KeyboardInterrupt()
        if not stop_requests.request(error):
            raise error

    def terminate(signum, frame) -> None:
        if os.getpid() != command_pid:
            _end_quietly(signum)
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        error = Terminated()
        if not stop_requests.request(error):
            raise error

    signal.signal(signal.SIGINT, interrupt)
    signal.signal(signal.SIGTERM, terminate)


def _end_quietly(signum: int) -> None:
    """End this forked process by the signal's default action (terminate, no traceback)."""
    signal.signal(signum, signal.SIG_DFL)
    os.kill(os.getpid(), signum)
