"""`--view`: the live browser view of a testbed command (crest/view/live_view.py)."""
from __future__ import annotations

import argparse
from contextlib import nullcontext

from crest.config import TestbedConfig
from crest.view.no_view import NoView
from model import CatheterParams


def add_view_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--view", action="store_true",
                        help="serve a live view with an E-STOP button on 127.0.0.1 (the link is printed)")


def view_for(args: argparse.Namespace, config: TestbedConfig, params: CatheterParams):
    """The live view if --view was given, else a stand-in that shows nothing (a context manager).
    The view's module (its server: bokeh and tornado, about a second to import) is imported only
    for --view, so that every other start is that much quicker."""
    if not args.view:
        return nullcontext(NoView())
    from crest.view.live_view import live_view
    return live_view(True, config, params.tendon_offset_mm, f"crest {args.command}")
