"""Run a function in a forked process of its own session, with a time limit.

The model's compiled solver holds the interpreter while it runs, so a solve that never returns
(see the blind benchmark) cannot be interrupted from inside the process. Run in a child that
leads its own process group, it is ended from outside: on time-out the whole group (the child
and any workers it started) is killed, and nothing else.
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

    Raises CallTimedOut after timeout_s seconds without a result.
    """
    context = multiprocessing.get_context("fork")
    receiver, sender = context.Pipe(duplex=False)
    child = context.Process(target=_run_in_own_session, args=(sender, function, args, kwargs))
    child.start()
    sender.close()
    try:
        if not receiver.poll(timeout_s):
            os.killpg(child.pid, signal.SIGKILL)
            raise CallTimedOut(f"{function.__name__} did not return within {timeout_s:.0f} s")
        failed, value = receiver.recv()
    finally:
        child.join()
        receiver.close()
    if failed:
        raise value
    return value


def _run_in_own_session(sender, function: Callable, args: tuple, kwargs: dict) -> None:
    os.setsid()
    try:
        sender.send((False, function(*args, **kwargs)))
    except Exception as error:  # any failure of the call is handed to the caller, who decides
        sender.send((True, error))
    finally:
        sender.close()
