"""`crest view LOG.csv`: replay a recorded log in the browser (the live view's panels, a timeline)."""
from __future__ import annotations

import argparse
import threading
from pathlib import Path

from crest.view.replay_view import ReplayView


def add_parser(sub) -> None:
    parser = sub.add_parser("view", help="replay a recorded log in the browser, on a timeline (127.0.0.1)")
    parser.add_argument("log", type=Path, help="a crest log (.csv with its .json sidecar)")
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    view = ReplayView(args.log)                 # a bad log is refused before anything is served
    url = view.server.start()
    print(f"replay of {args.log}: {url}", flush=True)
    print("serving until Ctrl-C", flush=True)
    try:
        threading.Event().wait()
    except KeyboardInterrupt:
        print("replay ended")
        return 0
    finally:
        view.server.stop()
