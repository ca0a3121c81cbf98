"""A progress bar on stderr for long runs (throttled; one final line when done)."""
from __future__ import annotations

import sys
import time


class ProgressBar:
    def __init__(self, total: int, label: str, stream=sys.stderr, width: int = 30, interval_s: float = 0.2):
        self.total = max(int(total), 1)
        self.label = label
        self.stream = stream
        self.width = width
        self.interval_s = interval_s
        self._last_s = 0.0
        self._finished = False
        self._tty = getattr(stream, "isatty", lambda: False)()

    def update(self, done: int) -> None:
        if self._finished:
            return
        now = time.monotonic()
        if done < self.total and now - self._last_s < (self.interval_s if self._tty else 5.0):
            return
        self._last_s = now
        fraction = min(done / self.total, 1.0)
        filled = int(round(fraction * self.width))
        bar = "#" * filled + "." * (self.width - filled)
        end = "\r" if self._tty and done < self.total else "\n"
        self._finished = done >= self.total
        self.stream.write(f"{self.label} [{bar}] {fraction * 100:5.1f}%{end}")
        self.stream.flush()

    def finish(self) -> None:
        self.update(self.total)
