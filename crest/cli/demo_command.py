"""`crest demo`: the whole stack on the virtual testbed.

Boots the five simulated drives, homes, and runs the paper's circle scenario (Fig. 4.3) twice,
with the constant-curvature controller and with the friction-aware Dahl feedforward, recording
both runs. On the virtual testbed it says which plant runs behind the drives: by default the Dahl
family, the controller's own model with other parameters (an in-family comparison);
`--plant-config configs/rod_plant.toml` runs it on the independent rod plant (out of family).
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

from control import make_controller
from crest.cli.common_options import add_testbed_options, check_output, motion_plan, session_options
from crest.cli.progress import ProgressBar
from crest.cli.view_option import add_view_option, view_for
from crest.experiment.builtin_trajectories import BuiltinOptions, builtin_trajectory
from crest.experiment.controlled_run import run_with_controller
from crest.experiment.recorder import ExperimentRecorder
from crest.session import open_session

DEMO_ARTICULATION_DEG = 120.0
DEMO_INSERTION_MM = 60.0


def add_parser(sub) -> None:
    parser = sub.add_parser("demo", help="the whole stack on the virtual testbed: boot, home, paper scenario, logs")
    parser.add_argument("--catheter", type=Path, default=None, help="the controller's catheter parameters TOML")
    parser.add_argument("--record", type=Path, default=Path("runs"), help="directory for the logs (default runs/)")
    add_testbed_options(parser)
    add_view_option(parser)
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    check_output(args.record, directory=True)                      # refused before anything moves
    plan = motion_plan(args)
    config, params, workspace, limits, period_s = plan.config, plan.params, plan.workspace, plan.limits, plan.period_s
    options = BuiltinOptions(articulation_deg=DEMO_ARTICULATION_DEG, insertion_mm=DEMO_INSERTION_MM)
    trajectory = builtin_trajectory("circle", workspace, limits, options, period_s, plan.start)
    out_dir = args.record / f"demo-{time.strftime('%Y%m%d-%H%M%S')}"
    results = {}
    with view_for(args, config, params) as view, open_session(session_options(args)) as session:
        view.attach(session)
        where = "the virtual testbed" if session.backend.is_virtual else "the testbed"
        print(f"booted 5 axes on {where} ({config.bus.interface}:{config.bus.channel}, "
              f"SYNC {1 / period_s:.0f} Hz)")
        plant = session.backend.plant
        if plant is not None:
            print(f"plant: {plant}")
        session.testbed.home()
        print("homed; running the paper's circle (Fig. 4.3) at "
              f"{DEMO_ARTICULATION_DEG:.0f} deg articulation, {DEMO_INSERTION_MM:.0f} mm free length")
        for name in ("cc", "dahl"):
            controller = make_controller(name, workspace, limits, period_s)
            recorder = ExperimentRecorder(session, out_dir / f"circle-{name}.csv", params,
                                          source=f"crest demo, circle with {name}")
            progress = ProgressBar(len(trajectory), f"circle with {name:<5}")
            on_cycle = view.follow(f"demo: circle with {name}", trajectory.tip_mm, len(trajectory),
                                   progress.update)
            result = run_with_controller(session, trajectory, controller, recorder=recorder, on_cycle=on_cycle)
            progress.finish()
            recorder.close({"rms_tip_error_mm": result.rms_tip_error_mm})
            results[name] = result
    for name, result in results.items():
        lost = result.tip_coverage.loss_sentence()
        print(f"{name:>5}: RMS tip error {result.rms_tip_error_mm:.2f} mm over {result.tip_samples} tracker "
              f"samples" + (f"; {lost}" if lost else "") + f"; log {result.log_path}")
    cc, dahl = results["cc"].rms_tip_error_mm, results["dahl"].rms_tip_error_mm
    print(f"the friction-aware feedforward cuts the tip error by {100 * (1 - dahl / cc):.0f}% "
          "against constant curvature" + (f"\n  on the plant: {plant}" if plant is not None else ""))
    print(f"logs are in {out_dir}/ (CSV + JSON sidecar + CAN traffic .blf)")
    return 0
