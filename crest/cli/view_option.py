"""`--view`: the live browser view of a testbed command (crest/view/live_view.py)."""
from __future__ import annotations

import argparse

from crest.config import TestbedConfig
from crest.view.live_view import live_view
from model import CatheterParams


def add_view_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--view", action="store_true",
                        help="serve a live view with an E-STOP button on 127.0.0.1 (the link is printed)")


def view_for(args: argparse.Namespace, config: TestbedConfig, params: CatheterParams):
    """The live view if --view was given, else a stand-in that shows nothing (a context manager)."""
    return live_view(args.view, config, params.tendon_offset_mm, f"crest {args.command}")
