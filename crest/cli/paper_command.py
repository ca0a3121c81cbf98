"""`crest paper --out DIR`: reproduce the seed paper's simulation studies (Figs. 3.1-4.4)."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from crest.cli.common_options import check_output
from crest.paper import SUMMARY, PaperSettings, reproduce
from model import CatheterParams


def add_parser(sub) -> None:
    parser = sub.add_parser("paper", help="reproduce the seed paper's figures with the model")
    parser.add_argument("--out", required=True, type=Path, help="directory for the PNG figures and summary.json")
    parser.add_argument("--catheter", default=None, help="catheter parameters TOML (default configs/catheter.toml)")
    parser.add_argument("--elements", type=int, default=20, help="lumped elements (default 20, as in the paper)")
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    check_output(args.out, directory=True)                         # refused now, not after the figures
    params = CatheterParams.from_toml(args.catheter) if args.catheter else CatheterParams.from_toml()
    summary = reproduce(args.out, PaperSettings(params, n_elements=args.elements), progress=sys.stderr)
    headline = summary["headline"]
    print(f"wrote {len(summary['figures'])} figures and {SUMMARY} to {args.out}")
    print(f"at 180 deg the friction model's tip is {headline['cc_vs_friction_tip_difference_at_180_deg_cm']:.2f} cm "
          f"from constant curvature (paper, against its prototype: {headline['paper_friction_model_error_cm']} cm "
          f"with friction, {headline['paper_constant_curvature_error_cm']} cm constant curvature)")
    return 0
