"""The control loop's hand-off to the live view: a bounded deque, appended to without blocking.

The loop calls ``put`` once per SYNC cycle (``Testbed.observe_cycles``). ``deque.append`` with a
``maxlen`` is one atomic operation under the GIL: no lock, no I/O, no allocation that grows, so the
loop never waits for the view. The view thread takes everything queued with ``drain`` about 30
times a second; if it falls behind by more than ``capacity`` cycles, the oldest are dropped
(the view shows the newest state, it does not log).
"""
from __future__ import annotations

from collections import deque

from crest.driver import CycleSample

DEFAULT_CAPACITY = 1024
"""Cycles kept for the view: over 2 s at 500 Hz SYNC, far more than one 10 Hz screen frame needs."""


class SampleSlot:
    def __init__(self, capacity: int = DEFAULT_CAPACITY) -> None:
        self._samples: deque[CycleSample] = deque(maxlen=capacity)

    def put(self, sample: CycleSample) -> None:
        """Loop side: queue one cycle's sample (never blocks)."""
        self._samples.append(sample)

    def drain(self) -> list[CycleSample]:
        """View side: every sample queued since the last drain, oldest first."""
        taken = []
        while True:
            try:
                taken.append(self._samples.popleft())
            except IndexError:
                return taken
