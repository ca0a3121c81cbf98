"""`crest status`: a table of the axes (NMT state, CiA 402 state, position, following error, fault), and on the
virtual testbed the plant behind the drives."""
from __future__ import annotations

import argparse
import time

from crest.cli.common_options import add_testbed_options, session_options
from crest.session import open_session

HEARTBEAT_WAIT_S = 0.3


def add_parser(sub) -> None:
    parser = sub.add_parser("status", help="show the state of every axis (does not reset the drives)")
    add_testbed_options(parser)
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    if args.fault:
        raise ValueError("--fault does not apply to status: it moves nothing, and fault times count from the "
                         "start of a command's motion (use it with run, move, jog, home, demo or excite)")
    with open_session(session_options(args, boot=False, tracker=False)) as session:
        time.sleep(HEARTBEAT_WAIT_S)   # learn each drive's NMT state from its heartbeat
        print(format_status(session.testbed.status()))
        if session.backend.plant is not None:
            print(f"plant: {session.backend.plant}")
    return 0


def format_status(rows) -> str:
    lines = [f"{'axis':<10} {'node':>4}  {'NMT':<16} {'CiA 402':<24} {'position mm':>12} {'foll. err mm':>12}  fault",
             "-" * 96]
    for row in rows:
        state = getattr(row.state, "name", str(row.state))
        lines.append(f"{row.axis:<10} {row.node_id:>4}  {str(row.nmt_state):<16} {state:<24} "
                     f"{row.position_mm:>12.3f} {row.following_error_mm:>12.3f}  {row.fault or '-'}")
    return "\n".join(lines)
