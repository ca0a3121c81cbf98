"""`crest`: the operator command line. A thin face: parsing, one-line errors, exit codes.

Every command runs on the virtual testbed unless --config names a real one.
"""
from __future__ import annotations

import argparse
import signal
import sys

from crest.cli import (bench_command, demo_command, estop_command, excite_command, fit_command, gap_command,
                       home_command, jog_command, move_command, paper_command, run_command, status_command,
                       testbed_command, view_command)
from crest.cli.common_options import add_debug_option
from crest.cli.compile_notice import announce_compiles
from crest.cli.library_logging import route_library_logging
from crest.config import ConfigError
from crest.driver import SafetyStop, Terminated
from crest.exit_codes import ExitCode

COMMANDS = {
    "demo": demo_command,
    "status": status_command,
    "home": home_command,
    "move": move_command,
    "run": run_command,
    "jog": jog_command,
    "estop": estop_command,
    "excite": excite_command,
    "paper": paper_command,
    "bench": bench_command,
    "fit": fit_command,
    "gap": gap_command,
    "view": view_command,
    "testbed": testbed_command,
}


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="crest", description="CREST catheter testbed: driver, model, control.")
    add_debug_option(parser, default=False)
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name, module in COMMANDS.items():
        module.add_parser(sub)
    for command_parser in sub.choices.values():      # `crest run ... --debug` as well as `crest --debug run ...`
        add_debug_option(command_parser)
    return parser


def _raise_terminated(signum, frame) -> None:
    """SIGTERM: stop like Ctrl-C. Later SIGTERMs are ignored, so a supervisor that repeats the
    signal cannot break off the stop the first one started (SIGKILL still ends the process)."""
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    raise Terminated()


def main(argv: list[str] | None = None) -> int:
    # A shell starts background commands with SIGINT ignored, and Python then never raises
    # KeyboardInterrupt. An interrupt (Ctrl-C, or `kill -INT` from a supervisor) must still stop
    # every axis and save the log, however crest was started. SIGTERM (`kill PID`, a service
    # manager) takes the same path with its own exit code.
    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.signal(signal.SIGTERM, _raise_terminated)
    parser = build_parser()
    args = parser.parse_args(argv)
    route_library_logging(args.debug)
    announce_compiles()
    try:
        return int(args.handler(args))
    except SafetyStop as stop:
        print(f"crest: safety stop: {stop}", file=sys.stderr)
        return int(stop.exit_code)
    except Terminated:
        print("crest: stopped by SIGTERM", file=sys.stderr)
        return int(ExitCode.TERMINATED)
    except KeyboardInterrupt:
        print("crest: stopped by Ctrl-C", file=sys.stderr)
        return int(ExitCode.INTERRUPTED)
    except ConfigError as exc:
        print(f"crest: configuration error: {exc}", file=sys.stderr)
        return int(ExitCode.CONFIG)
    except Exception as exc:  # the one place that turns any error into one line
        if args.debug:
            raise
        print(f"crest: error: {exc} (run with --debug for the traceback)", file=sys.stderr)
        return int(ExitCode.ERROR)


if __name__ == "__main__":
    sys.exit(main())
