"""`crest run TRAJECTORY`: a builtin paper scenario or a set-point CSV, with a progress bar."""
from __future__ import annotations

import argparse
import sys

from control import make_controller
from crest.cli.common_options import (add_controller_options, add_record_option, add_testbed_options,
                                      catheter_params, motion_plan, planned_record_path, positive_number,
                                      session_options)
from crest.cli.progress import ProgressBar
from crest.config import load_testbed_config
from crest.driver.motion_limits import check_trajectory
from crest.experiment.builtin_trajectories import BUILTINS, BuiltinOptions, builtin_trajectory
from crest.experiment.controlled_run import run_with_controller
from crest.experiment.recorder import ExperimentRecorder
from crest.experiment.setpoint_csv import read_setpoints
from crest.session import open_session


# The builtin options and the builtins that use them; any other use is refused, never ignored.
BUILTIN_OPTIONS = {
    "articulation_deg": ("--articulation-deg", ("sweep", "circle", "insertion", "history"), 90.0),
    "plane_deg": ("--plane-deg", ("sweep", "circle", "insertion", "history"), 0.0),
    "insertion_mm": ("--insertion-mm", ("circle", "insertion"), None),
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
                        help="builtin:circle and builtin:insertion: free length to use or reach")
    parser.add_argument("--periods", type=positive_number, default=None,
                        help="builtin:sweep: number of sweeps (a whole number); builtin:circle: circle turns "
                             "(> 0); default 1")
    add_controller_options(parser, default=DEFAULT_CONTROLLER)
    parser.set_defaults(controller=None)        # so that a CSV run can tell a --controller it cannot apply
    add_record_option(parser)
    add_testbed_options(parser)
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
    trajectory = builtin_trajectory(name, workspace, limits, options, period_s, plan.start)   # refused before motion
    controller = make_controller(controller_name, workspace, limits, period_s,
                                 loss_timeout_s=config.tracker.loss_timeout_s)
    with open_session(session_options(args)) as session:
        session.testbed.home()
        recorder = _recorder(session, args, log_path, params, f"builtin:{name} with {controller_name}")
        progress = ProgressBar(len(trajectory), f"{args.trajectory} ({controller_name})")
        result = run_with_controller(session, trajectory, controller, recorder=recorder,
                                     closed_loop=controller_name == "dahl+fb", on_cycle=progress.update)
        progress.finish()
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
    with open_session(session_options(args)) as session:
        session.testbed.home()
        recorder = _recorder(session, args, log_path, params, f"set-points {args.trajectory}", tip_ref=False)
        progress = ProgressBar(len(samples), args.trajectory)
        done = [0]

        def on_sample(sample):
            done[0] += 1
            tip = session.tracker.latest() if session.tracker else None
            if recorder:
                recorder.write(sample, tip.tip_mm if tip is not None else None)
            progress.update(done[0])

        session.testbed.run_trajectory(samples, on_sample=on_sample)
        progress.finish()
        if recorder:
            recorder.close()
    print(f"ran {len(samples)} set-points" + (f"; log: {recorder.path}" if recorder else ""))
    return 0


def _recorder(session, args, path, params, source, tip_ref=True):
    return (ExperimentRecorder(session, path, params, source=source, tip_ref=tip_ref, overwrite=args.overwrite)
            if path else None)


def _report(result) -> None:
    rms = "no tip samples" if result.rms_tip_error_mm is None else f"RMS tip error {result.rms_tip_error_mm:.2f} mm"
    print(f"ran {result.cycles} cycles; {rms}" + (f"; log: {result.log_path}" if result.log_path else ""),
          file=sys.stdout)
