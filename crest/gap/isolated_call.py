"""Run a function in a forked process of its own process group, with a time limit.

The model's compiled solver holds the interpreter while it runs, so a solve that never returns
(see the blind benchmark) cannot be interrupted from inside the process. Run in a child that
leads its own process group, it is ended from outside: on time-out the whole group (the child
and any workers it started) is killed, and nothing else.

Both the parent and the child put the child into its own group (as a shell does), so the group
exists before the parent starts waiting, however late the child is first scheduled.
"""
from __future__ import annotations

import multiprocessing
import os
import signal
from collections.abc import Callable


class CallTimedOut(RuntimeError):
    """The isolated call did not return within its time limit (its processes were killed)."""


def call_isolated(function: Callable, *args, timeout_s: float, **kwargs):
    """function(*args, **kwargs) in a forked child; its result, or its exception re-raised here.

    Raises CallTimedOut after timeout_s seconds without a result. On that, or on anything else
    that ends the wait here (Ctrl-C), the child's process group is killed before this returns.
    """
    context = multiprocessing.get_context("fork")
    receiver, sender = context.Pipe(duplex=False)
    child = context.Process(target=_run_in_own_group, args=(sender, function, args, kwargs))
    child.start()
    _lead_own_group(child.pid)
    sender.close()
    try:
        if not receiver.poll(timeout_s):
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
