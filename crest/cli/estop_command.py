"""`crest estop`: quick-stop every drive now, by SDO, from a second process."""
from __future__ import annotations

import argparse

from crest.backend import open_backend
from crest.cli.common_options import add_testbed_options
from crest.config import load_testbed_config
from crest.driver import emergency_stop


def add_parser(sub) -> None:
    parser = sub.add_parser("estop", help="quick-stop every drive (works beside a running crest process)")
    add_testbed_options(parser)
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    config = load_testbed_config(args.config)
    backend = open_backend(config)
    try:
        results = emergency_stop(backend.bus, config)
    finally:
        backend.close()
    failed = False
    for axis, result in results.items():
        state = getattr(result, "name", str(result))
        failed |= isinstance(result, Exception)
        print(f"{axis:<10} {state}")
    return 1 if failed else 0
