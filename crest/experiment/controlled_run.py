"""Run a trajectory on the testbed through a controller, one SYNC cycle per set-point.

Each cycle: the tip of a tracker frame new since the last cycle (if any), the controller's
command for the set-point, one SYNC cycle of the five axes, one log row. A controller that ignores
what was measured (``uses_feedback`` False: `cc`, `dahl`) computes the next set-point's command
while the drives answer this cycle's SYNC, off the cycle's critical path; the commands are the
same as computed one after the other, and an error in that command is raised once this cycle's
row is logged, where it would have been raised before. A controller that loses
the tracker in a closed-loop run, like the driver's own tracker watch, ends in a safety stop with
the TRACKER_LOST exit code; an open-loop run goes on, and its result says when the tracker was
lost and how many rows after it have a tip.
"""
from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from control import Controller, SetPoint, TendonCommand, TrackerLostError
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
    upcoming = iter(setpoints)
    setpoint = next(upcoming, None)
    ahead: _CommandAhead | None = None
    try:
        while setpoint is not None:
            measurement = feed.poll(setpoint.t_s)
            try:
                command = controller.command(setpoint, measurement, drive_tension_n=tension_n) \
                    if ahead is None else ahead.result()
            except TrackerLostError:
                testbed.report_tracker_loss(feed.age_s())
                testbed.cycle()          # carries the stop out and raises SafetyStop
                raise
            next_setpoint = next(upcoming, None)
            ahead = None if controller.uses_feedback or next_setpoint is None \
                else _CommandAhead(controller, next_setpoint)
            sample = testbed.cycle(AxisTargets(tuple(command.tendon_mm), command.insertion_mm), meanwhile=ahead)
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
            setpoint = next_setpoint
    finally:
        if closed_loop:
            testbed.watch_tracker(None)
    rms = float(np.sqrt(np.mean(squared_errors))) if squared_errors else None
    return RunResult(cycles, len(squared_errors), feed.frames, rms, recorder.path if recorder else None,
                     coverage)


class _CommandAhead:
    """The command for the next set-point of a controller without feedback, computed while the
    drives answer a SYNC; ``result`` returns it, or raises what computing it raised."""

    def __init__(self, controller: Controller, setpoint: SetPoint) -> None:
        self._controller = controller
        self._setpoint = setpoint
        self._command: TendonCommand | None = None
        self._error: Exception | None = None

    def __call__(self) -> None:
        try:
            self._command = self._controller.command(self._setpoint)
        except Exception as error:  # raised in result(), after this cycle's row is logged
            self._error = error

    def result(self) -> TendonCommand:
        if self._error is not None:
            raise self._error
        assert self._command is not None, "the cycle did not run the command ahead"
        return self._command
