"""`crest jog`: interactive keyboard jogging of pitch, yaw and insertion, or of one axis.

Keys: w/s pitch -/+, a/d yaw -/+ (articulation steps of 2 deg), r/f insertion +/- 1 mm;
1-4 select tendon1..tendon4 and 5 the insertion axis, then +/- move it by 0.2 mm (a tendon's
antagonistic partner pays out as much); 0 returns to articulation; space holds where it is; q quits.
The speed is capped, and a tension governor (control.tension_governor) slows the jog as a tendon
nears its max_tension_n and refuses motion that would load it further; a live status line shows
the state, and on exit every axis is stopped and released.
"""
from __future__ import annotations

import argparse
import copy
import math
import sys

import numpy as np

from control import Articulation, tendons_from_articulation
from control.path_tension import DEFAULT_TENSION_MARGIN, forecast_path_tension
from control.tension_governor import TensionGovernor
from crest.cli.common_options import (add_record_option, add_testbed_options, catheter_params, planned_record_path,
                                      session_options)
from crest.cli.keyboard import Keyboard
from crest.cli.view_option import add_view_option, view_for
from crest.config import load_testbed_config
from crest.driver import AXIS_ORDER, AxisTargets
from crest.experiment.recorder import ExperimentRecorder
from crest.experiment.workspace_from_config import workspace_for
from crest.session import open_session

ARTICULATION_STEP_DEG = 2.0
INSERTION_STEP_MM = 1.0
AXIS_STEP_MM = 0.2
JOG_SPEED_FRACTION = 0.25
STATUS_EVERY_CYCLES = 10
NOTICE_CYCLES = 200          # a refusal stays on the status line this long (2 s at 100 Hz)
CLEAR_TO_END = "\x1b[K"      # ANSI: erase the rest of the line, so a shorter status leaves no old text


def add_parser(sub) -> None:
    parser = sub.add_parser("jog", help="jog pitch, yaw, insertion or one axis from the keyboard")
    add_record_option(parser)
    add_testbed_options(parser)
    add_view_option(parser)
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
            step = AXIS_STEP_MM if key == "+" else -AXIS_STEP_MM
            values[index] += step
            if index < 4:         # the antagonistic partner (1/3, 2/4) pays out what the tendon pulls
                values[(index + 2) % 4] -= step
            self.axis_targets = AxisTargets(tuple(values[:4]), values[4])
            return True
        return False

    def describe(self) -> str:
        if self.axis is not None:
            return f"axis {self.axis}"
        return f"pitch {self.pitch_deg:+6.1f} deg  yaw {self.yaw_deg:+6.1f} deg  L {self.insertion_mm:5.1f} mm"


class JogGovernor:
    """The tension governor of the jog loop: judges each new target, slows or holds the motion."""

    def __init__(self, params, config, pretension_mm: float):
        axes = config.tendon_axes
        self.params = params
        self.pretension_mm = pretension_mm
        self.names = [axis.name for axis in axes]
        self.governor = TensionGovernor(tuple(axis.max_tension_n for axis in axes))
        self.speed_scale = 1.0
        self.notice = ""
        self.notice_cycles = 0

    def forecast_n(self, target: AxisTargets) -> np.ndarray:
        """The model's drive tensions at the target, from a straight catheter at its free length,
        raised by the forecast margin."""
        straight = [self.pretension_mm] * 4
        low, high = self.params.tendon_range_mm     # beyond it, the soft limits refuse the target anyway
        forecast = forecast_path_tension(self.params, [straight, np.clip(target.tendon_mm, low, high)],
                                         [target.insertion_mm, target.insertion_mm])
        return forecast.peak_n * (1.0 + DEFAULT_TENSION_MARGIN)

    def allows(self, measured_n, current: AxisTargets, target: AxisTargets) -> bool:
        """False (and a notice) when the change from current to target would load a tendon near its limit."""
        load = np.maximum(np.asarray(measured_n, dtype=float), self.forecast_n(target))
        verdict = self.governor.judge(load, current.tendon_mm, target.tendon_mm, current.insertion_mm,
                                      target.insertion_mm)
        if verdict.refused_tendon is None:
            return True
        self._refuse(verdict.refused_tendon, load)
        return False

    def holds(self, measured_n, position: AxisTargets, target: AxisTargets) -> bool:
        """True (and a notice) when the motion under way would load a tendon whose measured tension
        is already near its limit: the jog must stop where it is."""
        verdict = self.governor.judge(measured_n, position.tendon_mm, target.tendon_mm, position.insertion_mm,
                                      target.insertion_mm)
        if verdict.refused_tendon is None:
            return False
        self._refuse(verdict.refused_tendon, np.asarray(measured_n, dtype=float))
        return True

    def scale_for(self, measured_n) -> float:
        """The speed factor for the measured tensions, in steps of 0.1 (so targets are not re-sent every cycle)."""
        return max(self.governor.min_speed_scale, math.floor(self.governor.speed_scale(measured_n) * 10.0) / 10.0)

    def _refuse(self, k: int, load_n: np.ndarray) -> None:
        self.notice = (f"tension limit: {self.names[k]} {load_n[k]:.1f} N of {self.governor.max_tension_n[k]:g} N, "
                       f"pulling refused")
        self.notice_cycles = NOTICE_CYCLES

    def status(self) -> str:
        if self.notice_cycles > 0:
            return f" | {self.notice}"
        if self.speed_scale < 1.0:
            return f" | tension near the limit: speed {self.speed_scale:.0%}"
        return ""


def run(args: argparse.Namespace) -> int:
    params = catheter_params(args)
    status_open = False
    path = planned_record_path(args, "jog")
    config = load_testbed_config(args.config)
    with view_for(args, config, params) as view, open_session(session_options(args)) as session, \
            Keyboard() as keyboard:
        view.attach(session)
        view.follow("jog from the keyboard")
        try:
            testbed = session.testbed
            testbed.home()
            workspace = workspace_for(session.config, params)
            pretension_mm = session.config.coordination.pretension_mm
            state = JogState(workspace, testbed.positions().insertion_mm, pretension_mm)
            governor = JogGovernor(params, session.config, pretension_mm)
            recorder = (ExperimentRecorder(session, path, params, source="jog", tip_ref=False,
                                           overwrite=args.overwrite) if path else None)
            feed = session.tip_feed()
            print(__doc__.split("\n\n")[1], file=sys.stderr)
            session.start_fault_clock()
            sample = testbed.cycle()
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
                        continue
                    before = copy.copy(state)
                    if state.apply(key, testbed.commanded()):
                        if governor.allows(sample.tendon_tension_n, testbed.commanded(), state.targets()):
                            changed = True
                        else:
                            state = before
                measured = sample.tendon_tension_n
                if not changed and governor.holds(measured, testbed.positions(), testbed.commanded()):
                    state.axis_targets = testbed.positions()
                    changed = True
                scale = governor.scale_for(measured)
                if changed or scale != governor.speed_scale:
                    governor.speed_scale = scale
                    testbed.jog_to(state.targets(), speed_fraction=JOG_SPEED_FRACTION * scale)
                sample = testbed.cycle()
                measurement = feed.poll(sample.t_s)
                if recorder:
                    recorder.write(sample, None if measurement is None else measurement.tip_mm)
                cycles += 1
                governor.notice_cycles = max(0, governor.notice_cycles - 1)
                if cycles % STATUS_EVERY_CYCLES == 0:
                    tip = feed.latest_tip_mm
                    tip_text = "tip  --  " if tip is None else f"tip {tip[0]:6.1f} {tip[1]:6.1f} {tip[2]:6.1f} mm"
                    tension = " ".join(f"{t:4.1f}" for t in sample.tendon_tension_n)
                    sys.stderr.write(f"\r{state.describe()} | {tip_text} | T {tension} N{governor.status()}"
                                     f"{CLEAR_TO_END}")
                    sys.stderr.flush()
                    status_open = True
            if recorder:
                recorder.close()
        finally:
            if status_open:           # whatever ends the jog (q, a safety stop, Ctrl-C) starts on a new line
                sys.stderr.write("\n")
                sys.stderr.flush()
    print("jog ended: every axis stopped and released" + (f"; log: {recorder.path}" if recorder else ""))
    return 0
