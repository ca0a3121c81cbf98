"""`crest jog`: interactive keyboard jogging of pitch, yaw and insertion, or of one axis.

Keys: w/s pitch -/+, a/d yaw -/+ (articulation steps of 2 deg), r/f insertion +/- 1 mm;
1-4 select tendon1..tendon4 and 5 the insertion axis, then +/- move it by 0.2 mm; 0 returns to
articulation; space holds where it is; q quits. The speed is capped, a live status line shows
the state, and on exit every axis is stopped and released.
"""
from __future__ import annotations

import argparse
import math
import sys

from control import Articulation, tendons_from_articulation
from crest.cli.common_options import (add_record_option, add_testbed_options, catheter_params, planned_record_path,
                                      session_options)
from crest.cli.keyboard import Keyboard
from crest.driver import AXIS_ORDER, AxisTargets
from crest.experiment.recorder import ExperimentRecorder
from crest.experiment.workspace_from_config import workspace_for
from crest.session import open_session

ARTICULATION_STEP_DEG = 2.0
INSERTION_STEP_MM = 1.0
AXIS_STEP_MM = 0.2
JOG_SPEED_FRACTION = 0.25
STATUS_EVERY_CYCLES = 10


def add_parser(sub) -> None:
    parser = sub.add_parser("jog", help="jog pitch, yaw, insertion or one axis from the keyboard")
    add_record_option(parser)
    add_testbed_options(parser)
    parser.set_defaults(handler=run)


class JogState:
    """What the operator asked for: an articulation, or per-axis targets in axis mode."""

    def __init__(self, workspace, insertion_mm: float, pretension_mm: float):
        self.workspace = workspace
        self.pretension_mm = pretension_mm
        self.pitch_deg = 0.0
        self.yaw_deg = 0.0
        self.insertion_mm = insertion_mm
        self.axis: str | None = None
        self.axis_targets: AxisTargets | None = None

    def targets(self) -> AxisTargets:
        if self.axis_targets is not None:
            return self.axis_targets
        articulation = Articulation.from_bend((math.radians(self.pitch_deg), math.radians(self.yaw_deg)),
                                              self.insertion_mm)
        tendons = tendons_from_articulation(articulation, self.workspace.params.tendon_offset_mm, self.pretension_mm)
        return AxisTargets(tuple(tendons), self.insertion_mm)

    def apply(self, key: str, current: AxisTargets) -> bool:
        """Update the request for one key; True if the targets changed."""
        max_deg = math.degrees(self.workspace.max_articulation_rad)
        if key in "wsad":
            self.axis, self.axis_targets = None, None
            step = ARTICULATION_STEP_DEG * (1 if key in "sd" else -1)
            if key in "ws":
                self.pitch_deg = max(-max_deg, min(max_deg, self.pitch_deg + step))
            else:
                self.yaw_deg = max(-max_deg, min(max_deg, self.yaw_deg + step))
            return True
        if key in "rf":
            self.axis_targets = None
            step = INSERTION_STEP_MM if key == "r" else -INSERTION_STEP_MM
            self.insertion_mm = max(self.workspace.min_insertion_mm,
                                    min(self.workspace.max_insertion_mm, self.insertion_mm + step))
            return True
        if key in "12345":
            self.axis = AXIS_ORDER[int(key) - 1]
            self.axis_targets = current
            return False
        if key == "0":
            self.axis, self.axis_targets = None, None
            return True
        if key in "+-" and self.axis is not None:
            values = list(self.axis_targets.tendon_mm) + [self.axis_targets.insertion_mm]
            index = AXIS_ORDER.index(self.axis)
            values[index] += AXIS_STEP_MM if key == "+" else -AXIS_STEP_MM
            self.axis_targets = AxisTargets(tuple(values[:4]), values[4])
            return True
        return False

    def describe(self) -> str:
        if self.axis is not None:
            return f"axis {self.axis}"
        return f"pitch {self.pitch_deg:+6.1f} deg  yaw {self.yaw_deg:+6.1f} deg  L {self.insertion_mm:5.1f} mm"


def run(args: argparse.Namespace) -> int:
    params = catheter_params(args)
    path = planned_record_path(args, "jog")
    with open_session(session_options(args)) as session, Keyboard() as keyboard:
        testbed = session.testbed
        testbed.home()
        workspace = workspace_for(session.config, params)
        state = JogState(workspace, testbed.positions().insertion_mm, session.config.coordination.pretension_mm)
        recorder = (ExperimentRecorder(session, path, params, source="jog", tip_ref=False, overwrite=args.overwrite)
                    if path else None)
        feed = session.tip_feed()
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        cycles = 0
        while True:
            keys = keyboard.read()
            if "q" in keys or keyboard.closed:
                break
            changed = False
            for key in keys:
                if key == " ":
                    state.axis_targets = testbed.positions()
                    changed = True
                else:
                    changed |= state.apply(key, testbed.commanded())
            if changed:
                testbed.jog_to(state.targets(), speed_fraction=JOG_SPEED_FRACTION)
            sample = testbed.cycle()
            feed.poll(sample.t_s)
            if recorder:
                recorder.write(sample, feed.latest_tip_mm)
            cycles += 1
            if cycles % STATUS_EVERY_CYCLES == 0:
                tip = feed.latest_tip_mm
                tip_text = "tip  --  " if tip is None else f"tip {tip[0]:6.1f} {tip[1]:6.1f} {tip[2]:6.1f} mm"
                tension = " ".join(f"{t:4.1f}" for t in sample.tendon_tension_n)
                sys.stderr.write(f"\r{state.describe()} | {tip_text} | T {tension} N   ")
                sys.stderr.flush()
        if recorder:
            recorder.close()
    print("\njog ended: every axis stopped and released" + (f"; log: {recorder.path}" if recorder else ""))
    return 0
