"""Warnings as operator lines: `crest: warning: MESSAGE` on stderr, unless --debug.

Python prints a warning as "FILE:LINE: Category: message" followed by the source line that raised
it (a truncated log read by `crest gap` showed "/.../log_recordings.py:44: TruncatedLogWarning: ..."
and then "return [recording_from_log(read_log(path)) ...]"). The message is for the operator; the
file, the category and the source line are for a developer, so --debug keeps Python's own format.
"""
from __future__ import annotations

import sys
import warnings


def route_warnings(debug: bool) -> None:
    """Without ``debug``: each warning Python shows becomes one line `crest: warning: MESSAGE` on stderr."""
    if not debug:
        warnings.showwarning = _operator_line


def _operator_line(message, category, filename, lineno, file=None, line=None) -> None:
    print(f"crest: warning: {message}", file=sys.stderr if file is None else file, flush=True)
