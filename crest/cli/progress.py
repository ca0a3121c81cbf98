"""A progress bar on stderr for long runs (throttled; one final line when done or stopped).

The bar redraws at most every interval_s on a terminal and every 5 s otherwise, so a run that
stops between two redraws would leave an old fraction on screen (0.1 % for a sweep stopped
3.7 s in); `close` therefore always ends with the fraction actually reached, on its own line.
"""
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
        self._done = 0
        self._finished = False
        self._tty = getattr(stream, "isatty", lambda: False)()

    def update(self, done: int) -> None:
        if self._finished:
            return
        self._done = done
        now = time.monotonic()
        if done < self.total and now - self._last_s < (self.interval_s if self._tty else 5.0):
            return
        self._last_s = now
        end = "\r" if self._tty and done < self.total else "\n"
        self._finished = done >= self.total
        self._write(done, "", end)

    def finish(self) -> None:
        self.update(self.total)

    def close(self) -> None:
        """End the bar: if the run stopped early, one line with the fraction it reached."""
        if not self._finished:
            self._finished = True
            self._write(self._done, " stopped", "\n")

    def _write(self, done: int, suffix: str, end: str) -> None:
        fraction = min(done / self.total, 1.0)
        filled = int(round(fraction * self.width))
        bar = "#" * filled + "." * (self.width - filled)
        self.stream.write(f"{self.label} [{bar}] {fraction * 100:5.1f}%{suffix}{end}")
        self.stream.flush()
