"""`crest run TRAJECTORY`: a builtin paper scenario or a set-point CSV, with a progress bar."""
from __future__ import annotations

import argparse
import sys

from control import make_controller
from crest.cli.common_options import (add_controller_options, add_record_option, add_testbed_options,
                                      catheter_params, motion_plan, planned_record_path, positive_number,
                                      session_options)
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


# The builtin options and the builtins that use them; any other use is refused, never ignored.
BUILTIN_OPTIONS = {
    "articulation_deg": ("--articulation-deg", ("sweep", "circle", "insertion", "history"), 90.0),
    "plane_deg": ("--plane-deg", ("sweep", "circle", "insertion", "history"), 0.0),
    "insertion_mm": ("--insertion-mm", ("sweep", "circle", "insertion", "history"), None),
    "periods": ("--periods", ("sweep", "circle"), 1.0),
}
DEFAULT_CONTROLLER = "cc"


def add_parser(sub) -> None:
    parser = sub.add_parser("run", help="run a trajectory: builtin:sweep|circle|insertion|history or a set-point CSV")
    parser.add_argument("trajectory", help="builtin:NAME or a CSV with t, tendon_cmd_1..4, insertion_cmd "
                                           "(the tendon and insertion commands themselves: no controller applies)")
    parser.add_argument("--articulation-deg", type=float, default=None,
                        help="builtin: articulation angle (default 90)")
    parser.add_argument("--plane-deg", type=float, default=None,
                        help="builtin: bending plane (0 = toward tendon 1; default 0)")
    parser.add_argument("--insertion-mm", type=float, default=None,
                        help="builtin: free length to run at (sweep, circle, history; default the catheter's "
                             "working free length) or to reach (insertion)")
    parser.add_argument("--periods", type=positive_number, default=None,
                        help="builtin:sweep: number of sweeps (a whole number); builtin:circle: circle turns "
                             "(> 0); default 1")
    add_controller_options(parser, default=DEFAULT_CONTROLLER)
    parser.set_defaults(controller=None)        # so that a CSV run can tell a --controller it cannot apply
    add_record_option(parser)
    add_testbed_options(parser)
    add_view_option(parser)
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    config = load_testbed_config(args.config)
    if args.trajectory.startswith("builtin:"):
        return _run_builtin(args, config)
    return _run_csv(args, config)


def _builtin_options(args, name: str) -> BuiltinOptions:
    """The builtin's options; one it does not use is refused (it would be silently ignored)."""
    values = {}
    for field, (flag, users, default) in BUILTIN_OPTIONS.items():
        given = getattr(args, field)
        if given is not None and name not in users:
            raise ValueError(f"{flag} does not apply to builtin:{name}; it applies to "
                             + ", ".join(f"builtin:{user}" for user in users))
        values[field] = default if given is None else given
    return BuiltinOptions(**values)


def _run_builtin(args, config) -> int:
    name = args.trajectory.split(":", 1)[1]
    if name not in BUILTINS:
        raise ValueError(f"unknown trajectory {args.trajectory!r}; choose builtin:{', builtin:'.join(BUILTINS)} "
                         "or a set-point CSV")
    controller_name = args.controller or DEFAULT_CONTROLLER
    options = _builtin_options(args, name)
    log_path = planned_record_path(args, "run")
    plan = motion_plan(args)
    params, workspace, limits, period_s = plan.params, plan.workspace, plan.limits, plan.period_s
    start = builtin_start(name, workspace, options)
    trajectory = builtin_trajectory(name, workspace, limits, options, period_s, start)   # refused before motion
    start_targets = AxisTargets.from_pulls(0.0, 0.0, start.insertion_mm, workspace.pretension_mm)
    check_planned_tension(config, params, start_targets, trajectory.tendon_mm, trajectory.insertion_mm,
                          f"{args.trajectory} at {options.articulation_deg:g} deg, free length {start.insertion_mm:g} mm",
                          "lower --articulation-deg or lengthen the free length with --insertion-mm")
    controller = make_controller(controller_name, workspace, limits, period_s,
                                 loss_timeout_s=config.tracker.loss_timeout_s)
    with view_for(args, config, params) as view, open_session(session_options(args)) as session:
        view.attach(session)
        session.testbed.home()
        session.testbed.move_to(start_targets)        # out to the scenario's free length
        recorder = _recorder(session, args, log_path, params, f"builtin:{name} with {controller_name}")
        progress = ProgressBar(len(trajectory), f"{args.trajectory} ({controller_name})")
        on_cycle = view.follow(f"run {args.trajectory}, controller {controller_name}", trajectory.tip_mm,
                               len(trajectory), progress.update)
        try:
            result = run_with_controller(session, trajectory, controller, recorder=recorder,
                                         closed_loop=controller_name == "dahl+fb", on_cycle=on_cycle)
            progress.finish()
        finally:
            progress.close()
        if recorder:
            recorder.close({"rms_tip_error_mm": result.rms_tip_error_mm})
    _report(result)
    return 0


def _run_csv(args, config) -> int:
    if args.controller is not None:
        raise ValueError(f"--controller does not apply to a set-point file: {args.trajectory} holds the tendon and "
                         "insertion commands themselves, which the drives follow as they are. Drop --controller, "
                         "or run a builtin trajectory (builtin:sweep, ...) with it")
    given = [flag for field, (flag, _, _) in BUILTIN_OPTIONS.items() if getattr(args, field) is not None]
    if given:
        raise ValueError(f"{', '.join(given)} apply only to builtin trajectories, not to the set-point file "
                         f"{args.trajectory}")
    samples = read_setpoints(args.trajectory, config.sync.period_s)
    check_trajectory(config, samples)                 # refused before anything moves
    params = catheter_params(args)
    log_path = planned_record_path(args, "run")
    home = AxisTargets.from_pulls(0.0, 0.0, config.insertion_axis.home_position_mm, config.coordination.pretension_mm)
    check_planned_tension(config, params, home, [s.tendon_mm for s in samples], [s.insertion_mm for s in samples],
                          args.trajectory, "lower the pulls in the file or lengthen its free length (insertion_cmd)")
    with view_for(args, config, params) as view, open_session(session_options(args)) as session:
        view.attach(session)
        session.testbed.home()
        recorder = _recorder(session, args, log_path, params, f"set-points {args.trajectory}", tip_ref=False)
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
            session.start_fault_clock()
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


def _recorder(session, args, path, params, source, tip_ref=True):
    return (ExperimentRecorder(session, path, params, source=source, tip_ref=tip_ref, overwrite=args.overwrite)
            if path else None)


def _report(result) -> None:
    """One line: cycles, the cycles held for a late command and the cycles a drive answered too late
    if any, the tracker loss if any, the tip error over the cycles with a tip, the log."""
    rms = ("no tip samples" if result.rms_tip_error_mm is None
           else f"RMS tip error {result.rms_tip_error_mm:.2f} mm over {result.tip_samples} tracker samples")
    held = (f"{result.held_cycles} cycles held for a command not yet computed (the trajectory ran that much "
            "later)" if result.held_cycles else None)
    unanswered = (f"{result.unanswered_cycles} cycles without every drive's answer in time"
                  + (" (their rows leave those cells empty)" if result.log_path else "")
                  if result.unanswered_cycles else None)
    parts = [f"ran {result.cycles} cycles", held, unanswered, result.tip_coverage.loss_sentence(), rms,
             f"log: {result.log_path}" if result.log_path else None]
    print("; ".join(part for part in parts if part), file=sys.stdout)
