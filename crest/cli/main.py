"""`crest`: the operator command line. A thin face: parsing, one-line errors, exit codes.

Every command runs on the virtual testbed unless --config names a real one.
"""
from __future__ import annotations

import argparse
import sys

from crest.cli import bench_command, demo_command, paper_command
from crest.exit_codes import ExitCode

COMMANDS = {
    "demo": demo_command,
    "paper": paper_command,
    "bench": bench_command,
}


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="crest", description="CREST catheter testbed: driver, model, control.")
    parser.add_argument("--debug", action="store_true", help="show Python tracebacks on errors")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name, module in COMMANDS.items():
        module.add_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.handler(args))
    except KeyboardInterrupt:
        print("crest: stopped by Ctrl-C", file=sys.stderr)
        return int(ExitCode.INTERRUPTED)
    except Exception as exc:  # the one place that turns any error into one line
        if args.debug:
            raise
        print(f"crest: error: {exc} (run with --debug for the traceback)", file=sys.stderr)
        return int(ExitCode.ERROR)


if __name__ == "__main__":
    sys.exit(main())
