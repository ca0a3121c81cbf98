"""`crest demo`: the whole stack on the virtual testbed (grows with each layer)."""
from __future__ import annotations

import argparse

import numpy as np

from model import CatheterParams, ConstantCurvature, DahlCatheter, tendons_from_articulation


def add_parser(sub) -> None:
    parser = sub.add_parser("demo", help="run a paper scenario on the virtual testbed")
    parser.add_argument("--catheter", default=None, help="catheter parameters TOML (default configs/catheter.toml)")
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    params = CatheterParams.from_toml(args.catheter) if args.catheter else CatheterParams.from_toml()
    print("Articulation sweep 0 -> 180 deg in the x-z plane (tip in mm, base frame)")
    print(f"{'deg':>5} | {'constant curvature':^26} | {'Dahl, frictionless':^26} | {'Dahl, with friction':^26}")
    models = [DahlCatheter(params.frictionless()), DahlCatheter(params)]
    cc = ConstantCurvature(params)
    for degrees in range(0, 181, 30):
        u = tendons_from_articulation(np.deg2rad(degrees), 0.0, params.tendon_offset_mm)
        tips = [cc.tip_mm(u, params.free_length_mm)] + [m.move_to(u) for m in models]
        print(f"{degrees:5d} | " + " | ".join(f"{t[0]:8.2f}{t[1]:8.2f}{t[2]:8.2f}  " for t in tips))
    gap = np.linalg.norm(tips[2] - tips[0])
    print(f"At 180 deg friction moves the tip {gap:.1f} mm away from the constant-curvature prediction.")
    return 0
