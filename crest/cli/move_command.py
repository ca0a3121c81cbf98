"""`crest move --pitch DEG --yaw DEG --insertion MM`: a point move through the kinematics."""
from __future__ import annotations

import argparse
import math

import numpy as np

from control import articulation_from_pitch_yaw, make_controller
from control.trajectories import point_to_point
from crest.cli.common_options import (add_controller_options, add_record_option, add_testbed_options, motion_plan,
                                      planned_record_path, session_options)
from crest.cli.view_option import add_view_option, view_for
from crest.driver import AxisTargets
from crest.experiment.controlled_run import run_with_controller
from crest.experiment.planned_tension import check_planned_tension
from crest.experiment.recorder import ExperimentRecorder
from crest.session import open_session

MOVE_SPEED_FRACTION = 0.5
END_FRAME_TIMEOUT_S = 1.0     # longest wait for the frame that measures the end pose


def add_parser(sub) -> None:
    parser = sub.add_parser("move", help="move the tip to a pitch, yaw and insertion")
    parser.add_argument("--pitch", type=float, required=True, metavar="DEG", help="bend toward +x (tendon 1)")
    parser.add_argument("--yaw", type=float, required=True, metavar="DEG", help="bend toward +y (tendon 2)")
    parser.add_argument("--insertion", type=float, default=None, metavar="MM",
                        help="free length out of the support tube (default: stay at home)")
    add_controller_options(parser)
    add_record_option(parser)
    add_testbed_options(parser)
    add_view_option(parser)
    parser.set_defaults(handler=run)


def _check_target(args: argparse.Namespace) -> None:
    for flag, value, unit in (("--pitch", args.pitch, "degrees"), ("--yaw", args.yaw, "degrees"),
                              ("--insertion", args.insertion, "mm of free length")):
        if value is not None and not math.isfinite(value):
            raise ValueError(f"{flag} {value}: give a finite number of {unit}")


def run(args: argparse.Namespace) -> int:
    _check_target(args)
    path = planned_record_path(args, "move")
    plan = motion_plan(args)
    config, params, workspace, limits, start = plan.config, plan.params, plan.workspace, plan.limits, plan.start
    insertion = args.insertion if args.insertion is not None else start.insertion_mm
    target = articulation_from_pitch_yaw(math.radians(args.pitch), math.radians(args.yaw), insertion)
    trajectory = point_to_point(workspace, limits, waypoints=[target],          # refused before motion
                                tendon_velocity_mm_s=MOVE_SPEED_FRACTION * limits.tendon_velocity_mm_s,
                                tendon_acceleration_mm_s2=MOVE_SPEED_FRACTION * limits.tendon_acceleration_mm_s2,
                                period_s=config.sync.period_s, start=start)
    check_planned_tension(config, params, AxisTargets.from_pulls(0.0, 0.0, start.insertion_mm, workspace.pretension_mm),
                          trajectory.tendon_mm, trajectory.insertion_mm,
                          f"move to pitch {args.pitch:g} deg, yaw {args.yaw:g} deg at free length {insertion:g} mm",
                          "lower the articulation or lengthen the free length with --insertion MM")
    controller = make_controller(args.controller, workspace, limits, config.sync.period_s,
                                 loss_timeout_s=config.tracker.loss_timeout_s)
    with view_for(args, config, params) as view, open_session(session_options(args)) as session:
        view.attach(session)
        session.testbed.home()
        recorder = (ExperimentRecorder(session, path, params, source=f"move with {args.controller}",
                                       overwrite=args.overwrite) if path else None)
        on_cycle = view.follow(f"move to pitch {args.pitch:g} deg, yaw {args.yaw:g} deg, controller "
                               f"{args.controller}", trajectory.tip_mm, len(trajectory))
        result = run_with_controller(session, trajectory, controller, recorder=recorder,
                                     closed_loop=args.controller == "dahl+fb", on_cycle=on_cycle)
        lost = result.tip_coverage.loss_sentence()
        # a frame requested now measures the end pose, while the tracker is still there
        tip = None
        if session.tracker and lost is None:
            try:
                tip = session.tracker.fresh_sample(END_FRAME_TIMEOUT_S)
            except TimeoutError as exc:
                lost = str(exc)
        if recorder:
            recorder.close()
    goal = trajectory.tip_mm[-1]
    print(f"target tip  {np.array2string(goal, precision=2)} mm")
    if tip is not None and tip.tip_mm is not None:
        print(f"tracked tip {np.array2string(np.asarray(tip.tip_mm), precision=2)} mm, "
              f"{np.linalg.norm(tip.tip_mm - goal):.2f} mm from the target")
    if lost:
        print(f"no tracked tip at the end: {lost}")
    if recorder:
        print(f"log: {recorder.path}")
    return 0
