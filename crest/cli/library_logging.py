"""Where the log records of the libraries under crest go: nowhere, unless --debug.

canopen and python-can report through Python's logging (canopen logs "Transfer aborted by client
with code 0x05040000" for every SDO timeout, for instance). With no handler configured, Python
prints such records of level WARNING and above to stderr, between crest's own lines. crest
reports every failure itself, in one line that names the axis and the remedy, so these records
are dropped; with --debug they are shown on stderr, prefixed with the library's logger name.
"""
from __future__ import annotations

import logging
import sys

LIBRARY_LOGGERS = ("canopen", "can")
SILENT = logging.CRITICAL + 1   # above every level: no record is made
DEBUG_LEVEL = logging.INFO   # canopen's DEBUG records are per frame: too many at 100 SYNC cycles per second


def route_library_logging(debug: bool) -> None:
    """Without ``debug``: the library loggers make no records at all. With it: INFO and above to stderr."""
    for name in LIBRARY_LOGGERS:
        logger = logging.getLogger(name)
        if not debug:
            logger.setLevel(SILENT)
            continue
        handler = logging.StreamHandler(sys.stderr)
        handler.setFormatter(logging.Formatter("%(name)s: %(levelname)s: %(message)s"))
        logger.handlers[:] = [handler]
        logger.setLevel(DEBUG_LEVEL)
        logger.propagate = False   # once, even if someone configured a root handler too
