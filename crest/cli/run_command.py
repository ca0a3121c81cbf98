"""`crest run TRAJECTORY`: a builtin paper scenario or a set-point CSV, with a progress bar."""
from __future__ import annotations

import argparse
import sys

from control import make_controller
from crest.cli.common_options import (add_controller_options, add_record_option, add_testbed_options,
                                      catheter_params, motion_plan, record_path, session_options)
from crest.cli.progress import ProgressBar
from crest.cli.view_option import add_view_option, view_for
from crest.config import load_testbed_config
from crest.driver import AxisTargets
from crest.driver.motion_limits import check_trajectory
from crest.experiment.builtin_trajectories import BUILTINS, BuiltinOptions, builtin_start, builtin_trajectory
from crest.experiment.controlled_run import run_with_controller
from crest.experiment.planned_tension import check_planned_tension
from crest.experiment.recorder import ExperimentRecorder
from crest.experiment.setpoint_csv import read_setpoints
from crest.experiment.tip_coverage import TipCoverage
from crest.session import open_session


def add_parser(sub) -> None:
    parser = sub.add_parser("run", help="run a trajectory: builtin:sweep|circle|insertion|history or a set-point CSV")
    parser.add_argument("trajectory", help="builtin:NAME or a CSV with t, tendon_cmd_1..4, insertion_cmd")
    parser.add_argument("--articulation-deg", type=float, default=90.0, help="builtin: articulation angle")
    parser.add_argument("--plane-deg", type=float, default=0.0, help="builtin: bending plane (0 = toward tendon 1)")
    parser.add_argument("--insertion-mm", type=float, default=None, help="builtin: free length to use or reach")
    parser.add_argument("--periods", type=float, default=1.0, help="builtin: sweeps or circle turns")
    add_controller_options(parser)
    add_record_option(parser)
    add_testbed_options(parser)
    add_view_option(parser)
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    config = load_testbed_config(args.config)
    if args.trajectory.startswith("builtin:"):
        return _run_builtin(args, config)
    return _run_csv(args, config)


def _run_builtin(args, config) -> int:
    name = args.trajectory.split(":", 1)[1]
    if name not in BUILTINS:
        raise ValueError(f"unknown trajectory {args.trajectory!r}; choose builtin:{', builtin:'.join(BUILTINS)} "
                         "or a set-point CSV")
    plan = motion_plan(args)
    params, workspace, limits, period_s = plan.params, plan.workspace, plan.limits, plan.period_s
    options = BuiltinOptions(args.articulation_deg, args.plane_deg, args.insertion_mm, args.periods)
    start = builtin_start(name, workspace, options)
    trajectory = builtin_trajectory(name, workspace, limits, options, period_s, start)   # refused before motion
    start_targets = AxisTargets.from_pulls(0.0, 0.0, start.insertion_mm, workspace.pretension_mm)
    check_planned_tension(config, params, start_targets, trajectory.tendon_mm, trajectory.insertion_mm,
                          f"{args.trajectory} at {args.articulation_deg:g} deg, free length {start.insertion_mm:g} mm",
                          "lower --articulation-deg or lengthen the free length with --insertion-mm")
    controller = make_controller(args.controller, workspace, limits, period_s,
                                 loss_timeout_s=config.tracker.loss_timeout_s)
    with view_for(args, config, params) as view, open_session(session_options(args)) as session:
        view.attach(session)
        session.testbed.home()
        session.testbed.move_to(start_targets)        # out to the scenario's free length
        recorder = _recorder(session, args, params, f"builtin:{name} with {args.controller}")
        progress = ProgressBar(len(trajectory), f"{args.trajectory} ({args.controller})")
        on_cycle = view.follow(f"run {args.trajectory}, controller {args.controller}", trajectory.tip_mm,
                               len(trajectory), progress.update)
        try:
            result = run_with_controller(session, trajectory, controller, recorder=recorder,
                                         closed_loop=args.controller == "dahl+fb", on_cycle=on_cycle)
            progress.finish()
        finally:
            progress.close()
        if recorder:
            recorder.close({"rms_tip_error_mm": result.rms_tip_error_mm})
    _report(result)
    return 0


def _run_csv(args, config) -> int:
    samples = read_setpoints(args.trajectory, config.sync.period_s)
    check_trajectory(config, samples)                 # refused before anything moves
    params = catheter_params(args)
    home = AxisTargets.from_pulls(0.0, 0.0, config.insertion_axis.home_position_mm, config.coordination.pretension_mm)
    check_planned_tension(config, params, home, [s.tendon_mm for s in samples], [s.insertion_mm for s in samples],
                          args.trajectory, "lower the pulls in the file or lengthen its free length (insertion_cmd)")
    with view_for(args, config, params) as view, open_session(session_options(args)) as session:
        view.attach(session)
        session.testbed.home()
        recorder = _recorder(session, args, params, f"set-points {args.trajectory}", tip_ref=False)
        progress = ProgressBar(len(samples), args.trajectory)
        on_cycle = view.follow(f"run set-points {args.trajectory}", None, len(samples), progress.update)
        feed = session.tip_feed()
        coverage = TipCoverage(config.tracker.loss_timeout_s if session.tracker is not None else None)

        def on_sample(sample):
            measurement = feed.poll(sample.t_s)
            tip = None if measurement is None else measurement.tip_mm
            if recorder:
                recorder.write(sample, tip)
            coverage.add(sample.t_s, tip is not None)
            on_cycle(coverage.rows)

        try:
            session.testbed.run_trajectory(samples, on_sample=on_sample)
            progress.finish()
        finally:
            progress.close()
        if recorder:
            recorder.close()
    parts = [f"ran {len(samples)} set-points", coverage.loss_sentence(),
             f"log: {recorder.path}" if recorder else None]
    print("; ".join(part for part in parts if part))
    return 0


def _recorder(session, args, params, source, tip_ref=True):
    path = record_path(args.record, "run")
    return ExperimentRecorder(session, path, params, source=source, tip_ref=tip_ref) if path else None


def _report(result) -> None:
    """One line: cycles, the tracker loss if any, the tip error over the cycles with a tip, the log."""
    rms = ("no tip samples" if result.rms_tip_error_mm is None
           else f"RMS tip error {result.rms_tip_error_mm:.2f} mm over {result.tip_samples} tracker samples")
    parts = [f"ran {result.cycles} cycles", result.tip_coverage.loss_sentence(), rms,
             f"log: {result.log_path}" if result.log_path else None]
    print("; ".join(part for part in parts if part), file=sys.stdout)
