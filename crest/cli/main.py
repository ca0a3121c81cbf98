"""`crest`: the operator command line. A thin face: parsing, one-line errors, exit codes.

Every command runs on the virtual testbed unless --config names a real one.
"""
from __future__ import annotations

import argparse
import importlib
import sys

from crest.cli.compile_notice import announce_compiles
from crest.cli.debug_option import add_debug_option
from crest.cli.library_logging import route_library_logging
from crest.cli.stop_signals import install_stop_signals
from crest.cli.warning_lines import route_warnings
from crest.config import ConfigError
from crest.driver import SafetyStop, Terminated
from crest.exit_codes import ExitCode

COMMANDS = ("demo", "status", "home", "move", "run", "jog", "estop", "excite", "paper", "bench", "fit", "gap", "view",
            "testbed")
"""Each command is crest/cli/NAME_command.py: its add_parser(sub), which sets the handler."""


def command_names(argv: list[str]) -> tuple[str, ...]:
    """The commands whose modules a start imports: only the one argv names, else all of them (for
    `crest --help` and for argparse's error that lists the choices). A command module imports what its
    handler needs (numba's kernels, filterpy, bokeh, matplotlib, ...): all of them together cost
    seconds at every start. The top level has no option that takes a value, so the first argument
    that is not an option is the command."""
    named = next((arg for arg in argv if not arg.startswith("-")), None)
    return (named,) if named in COMMANDS else COMMANDS


def build_parser(names: tuple[str, ...] = COMMANDS) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="crest", description="CREST catheter testbed: driver, model, control.")
    add_debug_option(parser, default=False)
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in names:
        importlib.import_module(f"crest.cli.{name}_command").add_parser(sub)
    for command_parser in sub.choices.values():      # `crest run ... --debug` as well as `crest --debug run ...`
        add_debug_option(command_parser)
    return parser


def main(argv: list[str] | None = None) -> int:
    install_stop_signals()          # Ctrl-C and SIGTERM stop the command, however it was started
    argv = sys.argv[1:] if argv is None else argv
    args = build_parser(command_names(argv)).parse_args(argv)
    route_library_logging(args.debug)
    route_warnings(args.debug)
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
