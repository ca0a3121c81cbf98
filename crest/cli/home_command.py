"""`crest home`: boot and home every axis; the tendon pairs end at their pretension."""
from __future__ import annotations

import argparse

from crest.cli.common_options import add_testbed_options, session_options
from crest.cli.status_command import format_status
from crest.session import open_session


def add_parser(sub) -> None:
    parser = sub.add_parser("home", help="boot and home all five axes")
    add_testbed_options(parser)
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    with open_session(session_options(args, tracker=False)) as session:
        session.start_fault_clock()
        session.testbed.home()
        print(format_status(session.testbed.status()))
        print("homed: tendons at their pretension, insertion at its home position")
    return 0
