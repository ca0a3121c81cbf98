"""Ctrl-C and SIGTERM while a session holds the testbed: taken at the cycle's safe point, never mid-frame.

Python runs a signal's handler in the main thread between two bytecodes, wherever that thread is.
An exception the handler raises can land inside library code that holds a lock, for instance in
``queue.Queue.put`` (python-can's virtual bus hands every frame to each receiver's queue) after
``Condition.__enter__`` has taken the queue's lock and before the ``with`` block that would release
it. The lock stays held: the receiving thread that needs it waits forever, that drive answers no
further SYNC, and the stop itself blocks on the next frame it hands to that queue. (Seen in CI: a
``crest run --fast`` given Ctrl-C printed no stop and was killed 60 s later. In isolation, a
SIGALRM handler that raised during ``VirtualBus.send`` left a receiver's queue locked for good.)

So inside ``at_safe_points`` (the whole of ``crest.session.open_session``) the CLI's handlers only
*request* the stop: ``request`` keeps the exception, and ``raise_requested`` raises it where the
main thread holds no lock, at the start of every supervised cycle (``CycleRunner.cycle``). From
there it takes the path it always took: the driver call turns it into the stop of every axis. It
comes at most one SYNC cycle late while the testbed cycles. Where the main thread waits between
cycles it comes once the wait is over: an SDO exchange (the boot's, a mode change's: at most its
SDO timeout), and in simulated time the wait for a tracker frame (at most STALLED_TRACKER_TIMEOUT_S
and, once per loss of the link, RECONNECT_GRACE_S of wall time, crest.experiment.tip_feed: 7 s, in
which simulated time and so the drives stand still). A stop requested once the last cycle is over
is raised when the block ends, after every part of the session is closed, unless an exception
already ends the block (that stop is under way).

Outside the block, or without the CLI's handlers (a script using the driver), a signal raises
at once, as it does by default.
"""
from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

_depth = 0                                 # open at_safe_points blocks
_requested: BaseException | None = None    # the first stop requested in them


def request(error: BaseException) -> bool:
    """From a signal handler: inside a block, keep ``error`` (the first one counts) for the next
    safe point and return True; outside one return False (the handler raises it at once)."""
    global _requested
    if _depth == 0:
        return False
    if _requested is None:
        _requested = error
    return True


def raise_requested() -> None:
    """A safe point: raise the stop requested since the last one, if any."""
    global _requested
    error, _requested = _requested, None
    if error is not None:
        raise error


@contextmanager
def at_safe_points() -> Iterator[None]:
    """Signals in the block are taken at its safe points (module doc)."""
    global _depth, _requested
    _depth += 1
    try:
        yield
    except BaseException:
        _depth -= 1
        if _depth == 0:
            _requested = None      # the block ends in an exception already; the stop is under way
        raise
    _depth -= 1
    if _depth == 0:
        raise_requested()
