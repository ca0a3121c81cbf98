"""Non-blocking single-key input from the terminal (raw mode while in use)."""
from __future__ import annotations

import os
import select
import sys
import termios
import tty


class Keyboard:
    """`with Keyboard() as keys: keys.read()` returns the keys typed since the last call."""

    def __init__(self, stream=sys.stdin):
        self.stream = stream
        self.fd = stream.fileno()
        self._saved = None
        self.closed = False

    def __enter__(self) -> "Keyboard":
        if os.isatty(self.fd):
            self._saved = termios.tcgetattr(self.fd)
            tty.setcbreak(self.fd)
        return self

    def __exit__(self, *exc) -> None:
        if self._saved is not None:
            termios.tcsetattr(self.fd, termios.TCSADRAIN, self._saved)

    def read(self) -> str:
        """Keys waiting on the input, without blocking; sets `closed` at end of input."""
        keys = []
        while select.select([self.fd], [], [], 0)[0]:
            chunk = os.read(self.fd, 64)
            if not chunk:
                self.closed = True
                break
            keys.append(chunk.decode("utf-8", errors="ignore"))
        return "".join(keys)
