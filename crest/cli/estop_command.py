"""`crest estop`: quick-stop every drive now, by SDO, from a second process.

It reaches the drives of a hardware testbed, or of a served virtual testbed (`crest testbed serve`).
One line per axis on stdout. Success (exit 0) only when every axis answered and no longer shows
OPERATION ENABLED; an axis that could not be reached or did not stop fails the command (exit 1)
with one line on stderr naming the axes. A virtual testbed inside another crest process is out of
reach of any other process, so estop refuses it (exit 1) without opening anything.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from crest.backend import BackendError, join_bus
from crest.config import load_testbed_config
from crest.driver import Cia402State, SdoFailure, emergency_stop
from crest.exit_codes import ExitCode


def add_parser(sub) -> None:
    parser = sub.add_parser("estop", help="quick-stop every drive of a hardware or served virtual testbed (beside a running crest)")
    parser.add_argument("--config", type=Path, default=None,
                        help="the testbed configuration of the running testbed (its [bus]; the tracker is not used)")
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    config = load_testbed_config(args.config)
    try:
        bus = join_bus(config)
    except BackendError as exc:
        print(f"crest estop: nothing was stopped: {exc}", file=sys.stderr)
        return int(ExitCode.ERROR)
    try:
        results = emergency_stop(bus, config)
    finally:
        bus.shutdown()
    not_stopped = []
    for axis, result in results.items():
        if isinstance(result, SdoFailure):
            print(f"{axis:<10} NOT REACHED: {str(result).removeprefix(f'{axis}: ')}")
            not_stopped.append(axis)
        elif result is Cia402State.OPERATION_ENABLED:
            print(f"{axis:<10} NOT STOPPED: still OPERATION ENABLED after the quick stop")
            not_stopped.append(axis)
        else:
            print(f"{axis:<10} stopped ({result.value})")
    if not_stopped:
        print(f"crest estop: {len(not_stopped)} of {len(results)} axes are not known to be stopped "
              f"({', '.join(not_stopped)}); cut the drives' power", file=sys.stderr)
        return int(ExitCode.ERROR)
    return int(ExitCode.OK)
