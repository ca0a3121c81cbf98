"""`crest testbed serve`: the virtual testbed as its own process, reachable by other processes.

It prints where its CAN bus (python-can interface and channel) and its tracker's serial port are,
and writes them to a state file; while it runs, the other commands on the same configuration join
it instead of booting a virtual testbed of their own. Ctrl-C or SIGTERM stops it (exit 0).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from crest.cli.common_options import parse_effect
from crest.cli.debug_option import add_debug_option
from crest.config import load_testbed_config
from crest.driver import Terminated
from crest.exit_codes import ExitCode
from crest.testbed_service import TestbedAlreadyServed
from crest.testbed_service.serve import serve_until_stopped


def add_parser(sub) -> None:
    parser = sub.add_parser("testbed", help="serve the virtual testbed as its own process (crest testbed serve)")
    actions = parser.add_subparsers(dest="testbed_action", required=True, metavar="ACTION")
    serve = actions.add_parser("serve", help="run the virtual testbed's drives, plant and tracker in this process "
                                             "and serve its CAN bus on 127.0.0.1 until Ctrl-C")
    serve.add_argument("--config", type=Path, default=None,
                       help="testbed configuration (default configs/testbed.toml); its [bus] must be 'virtual'")
    serve.add_argument("--plant", default=None, metavar="MODULE:CLASS",
                       help="the plant behind the drives (default: the plant description's)")
    serve.add_argument("--plant-config", type=Path, default=None, metavar="PLANT.toml",
                       help="the plant description (default configs/virtual_plant.toml)")
    serve.add_argument("--effect", action="append", default=[], metavar="ID[:NAME=VALUE,...]",
                       help="switch on an unmodelled effect in the plant (repeatable), as for the other commands")
    serve.add_argument("--fault", action="append", default=[], metavar="AXIS:KIND@SECONDS",
                       help="inject a fault (repeatable), as for the other commands; SECONDS counts from the "
                            "testbed's start (from the start of the command's motion for a testbed a command started)")
    serve.add_argument("--port", type=_tcp_port, default=0,
                       help="TCP port of the CAN bus server on 127.0.0.1 (default 0: any free port)")
    serve.add_argument("--simulated-time", action="store_true",
                       help="move the testbed's clock only with the CANopen TIME stamps its master sends (a command "
                            "run with --fast), not with the wall clock: deterministic runs as fast as the computer allows")
    serve.add_argument("--parent-fd", type=int, default=None, help=argparse.SUPPRESS)   # auto_start.py's pipe
    add_debug_option(serve)
    parser.set_defaults(handler=run)


def _tcp_port(text: str) -> int:
    """argparse type: a TCP port number, 0-65535 (0: any free port)."""
    try:
        port = int(text)
    except ValueError:
        port = -1
    if not 0 <= port <= 65535:
        raise argparse.ArgumentTypeError(f"expected a TCP port 0-65535 (0: any free port), got {text!r}")
    return port


def run(args: argparse.Namespace) -> int:
    config = load_testbed_config(args.config)
    effects = dict(parse_effect(text) for text in args.effect)
    try:
        serve_until_stopped(config, plant=args.plant, plant_config=args.plant_config, effects=effects,
                            faults=args.fault, port=args.port, on_ready=_announce, parent_fd=args.parent_fd,
                            simulated_time=args.simulated_time)
    except TestbedAlreadyServed as exc:
        print(f"crest testbed serve: {exc}", file=sys.stderr)
        return int(ExitCode.ERROR)
    except Terminated:            # a KeyboardInterrupt too: named first
        print("crest testbed serve: stopped by SIGTERM", file=sys.stderr)
    except KeyboardInterrupt:
        print("crest testbed serve: stopped by Ctrl-C", file=sys.stderr)
    return int(ExitCode.OK)


def _announce(served, state_file: Path) -> None:
    print(f"crest testbed serve: the virtual testbed of {served.config} is running (pid {served.pid})\n"
          f"  CAN bus:    python-can interface '{served.bus_interface}', channel '{served.bus_channel}'\n"
          f"  tracker:    {served.tracker_port}\n"
          f"  plant:      {served.plant}\n"
          f"  state file: {state_file}\n"
          + (f"  CPU:        {', '.join(map(str, served.cpus))} (the commands that join it run on the others)\n"
             if served.cpus else "")
          + f"  threads:    {served.scheduling}\n"
          + ("  clock:      simulated: it moves only with the TIME stamps of a command run with --fast\n"
             if served.simulated_time else "")
          + "Other crest commands on this configuration join it now. Stop it with Ctrl-C "
          f"(or kill -TERM {served.pid}).", flush=True)
