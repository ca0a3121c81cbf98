"""Run a function in a forked process of its own process group, with a time limit.

The model's compiled solver holds the interpreter while it runs, so a solve that never returns
(see the blind benchmark) cannot be interrupted from inside the process. Run in a child that
leads its own process group, it is ended from outside: on time-out the whole group (the child
and any workers it started) is killed, and nothing else.

Both the parent and the child put the child into its own group (as a shell does), so the group
exists before the parent starts waiting, however late the child is first scheduled.

A call waited for in a thread other than the main one never sees Ctrl-C: it is ended through its
`cancel` event, which the main thread sets (the blind benchmark's cases run in threads).
"""
from __future__ import annotations

import multiprocessing
import os
import signal
import threading
import time
from collections.abc import Callable


CANCEL_POLL_S = 0.2


class CallTimedOut(RuntimeError):
    """The isolated call did not return within its time limit (its processes were killed)."""


class CallCancelled(RuntimeError):
    """The isolated call's cancel event was set before it returned (its processes were killed)."""


def call_isolated(function: Callable, *args, timeout_s: float, cancel: threading.Event | None = None, **kwargs):
    """function(*args, **kwargs) in a forked child; its result, or its exception re-raised here.

    Raises CallTimedOut after timeout_s seconds without a result, CallCancelled once `cancel` is
    set. On those, or on anything else that ends the wait here (Ctrl-C), the child's process group
    is killed before this returns.
    """
    context = multiprocessing.get_context("fork")
    receiver, sender = context.Pipe(duplex=False)
    child = context.Process(target=_run_in_own_group, args=(sender, function, args, kwargs))
    child.start()
    _lead_own_group(child.pid)
    sender.close()
    try:
        if not _wait(receiver, timeout_s, cancel):
            raise CallTimedOut(f"{function.__name__} did not return within {timeout_s:.0f} s")
        failed, value = receiver.recv()
    except BaseException:
        _kill_group(child.pid)
        raise
    finally:
        child.join()
        receiver.close()
    if failed:
        raise value
    return value


def _wait(receiver, timeout_s: float, cancel: threading.Event | None) -> bool:
    """True once the child's answer is ready, False after timeout_s; CallCancelled once `cancel` is set."""
    if cancel is None:
        return receiver.poll(timeout_s)
    deadline = time.monotonic() + timeout_s
    while not receiver.poll(max(0.0, min(CANCEL_POLL_S, deadline - time.monotonic()))):
        if cancel.is_set():
            raise CallCancelled("cancelled")
        if time.monotonic() >= deadline:
            return False
    return True


def _lead_own_group(pid: int) -> None:
    """setpgid(pid, pid); a child that has already ended needs no group."""
    try:
        os.setpgid(pid, pid)
    except ProcessLookupError:
        pass


def _kill_group(pid: int) -> None:
    """SIGKILL to every process of the group; a group whose processes have all ended is left."""
    try:
        os.killpg(pid, signal.SIGKILL)
    except ProcessLookupError:
        pass


def _run_in_own_group(sender, function: Callable, args: tuple, kwargs: dict) -> None:
    _lead_own_group(0)
    try:
        sender.send((False, function(*args, **kwargs)))
    except Exception as error:  # any failure of the call is handed to the caller, who decides
        sender.send((True, error))
    finally:
        sender.close()
