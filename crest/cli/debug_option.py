"""`--debug`: the one option every command shares, kept apart from the testbed options so that a
command that never touches the model (`crest estop`) does not import it to parse its arguments."""
from __future__ import annotations

import argparse


def add_debug_option(parser: argparse.ArgumentParser, default=argparse.SUPPRESS) -> None:
    """--debug, accepted before and after the command (a subcommand's copy must not reset the main one)."""
    parser.add_argument("--debug", action="store_true", default=default, help="show Python tracebacks on errors")
