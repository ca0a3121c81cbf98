"""Run a trajectory on the testbed through a controller, one SYNC cycle per set-point.

Each cycle: the tip of a tracker frame new since the last cycle (if any), the controller's
command for the set-point, one SYNC cycle of the five axes, one log row. A controller that loses
the tracker in a closed-loop run, like the driver's own tracker watch, ends in a safety stop with
the TRACKER_LOST exit code; an open-loop run goes on, and its result says when the tracker was
lost and how many rows after it have a tip.
"""
from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from control import Controller, SetPoint, TrackerLostError
from crest.driver import AxisTargets
from crest.experiment.recorder import ExperimentRecorder
from crest.experiment.tip_coverage import TipCoverage
from crest.session import Session


@dataclass(frozen=True)
class RunResult:
    """cycles: SYNC cycles run. tip_samples: cycles with a tip (a new tracker frame with the tool in
    view). tracker_frames: new tracker frames, with or without a tip. rms_tip_error_mm: against the
    set-points' tips, over the cycles with a tip (None without any). tip_coverage: the rows with a
    tip and the tracker loss, if any."""

    cycles: int
    tip_samples: int
    tracker_frames: int
    rms_tip_error_mm: float | None
    log_path: Path | None
    tip_coverage: TipCoverage


def run_with_controller(session: Session, setpoints: Iterable[SetPoint], controller: Controller, *,
                        recorder: ExperimentRecorder | None = None, closed_loop: bool = False,
                        on_cycle: Callable[[int], None] | None = None) -> RunResult:
    testbed = session.testbed
    if closed_loop and session.tracker is None:
        raise ValueError("a closed-loop run needs the tip tracker, and this session has none; nothing was moved")
    feed = session.tip_feed()
    coverage = TipCoverage(session.config.tracker.loss_timeout_s if session.tracker is not None else None)
    if closed_loop:
        testbed.watch_tracker(feed.age_s)
    controller.reset(insertion_mm=testbed.positions().insertion_mm)
    session.start_fault_clock()
    squared_errors: list[float] = []
    tension_n = None
    cycles = 0
    try:
        for setpoint in setpoints:
            measurement = feed.poll(setpoint.t_s)
            try:
                command = controller.command(setpoint, measurement, drive_tension_n=tension_n)
            except TrackerLostError:
                testbed.report_tracker_loss(feed.age_s())
                testbed.cycle()          # carries the stop out and raises SafetyStop
                raise
            sample = testbed.cycle(AxisTargets(tuple(command.tendon_mm), command.insertion_mm))
            tension_n = np.asarray(sample.tendon_tension_n, dtype=float)
            tip = None if measurement is None else measurement.tip_mm
            if recorder is not None:
                recorder.write(sample, tip, setpoint.tip_mm)
            coverage.add(sample.t_s, tip is not None)
            if tip is not None:
                squared_errors.append(float(np.sum((tip - setpoint.tip_mm) ** 2)))
            cycles += 1
            if on_cycle is not None:
                on_cycle(cycles)
    finally:
        if closed_loop:
            testbed.watch_tracker(None)
    rms = float(np.sqrt(np.mean(squared_errors))) if squared_errors else None
    return RunResult(cycles, len(squared_errors), feed.frames, rms, recorder.path if recorder else None,
                     coverage)
