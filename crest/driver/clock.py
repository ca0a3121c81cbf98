"""The host's clock: what paces SYNC and the host heartbeat, and what every driver timeout is measured in.

Two implementations of one small protocol (``now_s``, ``wait_until``):

- ``MonotonicClock``: wall time (``time.monotonic``), for hardware and for a virtual testbed
  whose drives are ticked in real time;
- ``SteppedClock``: simulated time that moves only when the driver waits for its next SYNC;
  ``on_advance(now_s)`` is called each time it moves (e.g. a simulated drive set's ``tick``),
  so a run is deterministic and as fast as the computer allows.

Waiting for a *reply* (SDO, boot-up, TPDO) is not done on this clock but on a condition with a
wall-time timeout: replies arrive in real time whichever clock paces the cycle.
"""

from __future__ import annotations

import time
from typing import Callable, Protocol


class Clock(Protocol):
    def now_s(self) -> float:
        """Seconds since the clock started."""

    def wait_until(self, deadline_s: float) -> None:
        """Return once ``now_s() >= deadline_s`` (at once if it already is)."""


class MonotonicClock:
    """Wall time since construction; ``wait_until`` sleeps."""

    def __init__(self) -> None:
        self._start_s = time.monotonic()

    def now_s(self) -> float:
        return time.monotonic() - self._start_s

    def wait_until(self, deadline_s: float) -> None:
        remaining_s = deadline_s - self.now_s()
        if remaining_s > 0.0:
            time.sleep(remaining_s)


class SteppedClock:
    """Simulated time: ``wait_until`` jumps to the deadline and reports it to ``on_advance``."""

    def __init__(self, on_advance: Callable[[float], None] | None = None, start_s: float = 0.0) -> None:
        self._now_s = start_s
        self._on_advance = on_advance

    def now_s(self) -> float:
        return self._now_s

    def wait_until(self, deadline_s: float) -> None:
        if deadline_s <= self._now_s:
            return
        self._now_s = deadline_s
        if self._on_advance is not None:
            self._on_advance(deadline_s)

    def advance(self, duration_s: float) -> None:
        """Let ``duration_s`` of simulated time pass (with nothing sent by the driver)."""
        self.wait_until(self._now_s + duration_s)
