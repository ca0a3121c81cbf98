"""Run a trajectory on the testbed through a controller, one SYNC cycle per set-point.

Each cycle: the tip of a tracker frame new since the last cycle (if any), the controller's
command for the set-point, one SYNC cycle of the five axes, one log row. A controller that ignores
what was measured (``uses_feedback`` False: `cc`, `dahl`) computes its commands off the cycle's
critical path: the next set-point's command while the drives answer this cycle's SYNC, or, below
a SYNC period of COMMAND_PROCESS_BELOW_S with the master under SCHED_FIFO, all of them ahead in a
process of its own (crest.experiment.command_process), where they do not hold the master's
interpreter lock. Measured at 500 Hz (README, "Where the commands are computed"): under SCHED_FIFO
the process took the missed cycles to 0 where the master had 5-7; under the normal scheduler it
added them (the busy worker delays the wake-ups of the cycle's threads, at nice 19 and even under
SCHED_IDLE), so there the commands stay in the master. The commands are the same as computed one
after the other, and an error in one is raised at its set-point, after the previous row is logged,
where it would have been raised before. A controller that loses
the tracker in a closed-loop run, like the driver's own tracker watch, ends in a safety stop with
the TRACKER_LOST exit code; an open-loop run goes on, and its result says when the tracker was
lost and how many rows after it have a tip.

For the run, the objects that exist at its start (the set-points, the model, the session) are
frozen out of the garbage collector (gc.freeze): a full collection over them took 10-46 ms, 5 to 23
missed SYNCs at 500 Hz, while the run's own short-lived objects are collected as before.
"""
from __future__ import annotations

import gc
from collections import deque
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from itertools import islice
from pathlib import Path

import numpy as np

from control import Controller, SetPoint, TendonCommand, TrackerLostError
from crest.driver import AxisTargets, Testbed
from crest.experiment.command_process import CommandProcess
from crest.experiment.recorder import ExperimentRecorder
from crest.experiment.tip_coverage import TipCoverage
from crest.session import Session

COMMAND_PROCESS_BELOW_S = 0.005   # SYNC periods this short leave no room for the dahl inversion in the master


@dataclass(frozen=True)
class RunResult:
    """cycles: SYNC cycles run. tip_samples: cycles with a tip (a new tracker frame with the tool in
    view). tracker_frames: new tracker frames, with or without a tip. rms_tip_error_mm: against the
    set-points' tips, over the cycles with a tip (None without any). tip_coverage: the rows with a
    tip and the tracker loss, if any. command_process: the commands came from a CommandProcess;
    held_cycles: cycles in which the testbed held its commands because the process's next command
    was not back yet (not counted in `cycles`, no row). unanswered_cycles: cycles in which at least
    one drive's answer to the SYNC did not come in time (its row has that axis' cells empty)."""

    cycles: int
    tip_samples: int
    tracker_frames: int
    rms_tip_error_mm: float | None
    log_path: Path | None
    tip_coverage: TipCoverage
    command_process: bool
    held_cycles: int
    unanswered_cycles: int


def run_with_controller(session: Session, setpoints: Iterable[SetPoint], controller: Controller, *,
                        recorder: ExperimentRecorder | None = None, closed_loop: bool = False,
                        on_cycle: Callable[[int], None] | None = None,
                        command_process: bool | None = None) -> RunResult:
    """command_process: compute the commands of a controller without feedback in a process of its own
    (CommandProcess); None (default) does so when the SYNC period is below COMMAND_PROCESS_BELOW_S and
    the master runs real-time (module doc)."""
    testbed = session.testbed
    if closed_loop and session.tracker is None:
        raise ValueError("a closed-loop run needs the tip tracker, and this session has none; nothing was moved")
    feed = session.tip_feed()
    coverage = TipCoverage(session.config.tracker.loss_timeout_s if session.tracker is not None else None)
    insertion_mm = testbed.positions().insertion_mm
    controller.reset(insertion_mm=insertion_mm)
    if command_process is None:
        command_process = commands_in_own_process(session, controller)
    commands = (_FromProcess(controller, setpoints, testbed, insertion_mm) if command_process
                else _InLoop(controller, setpoints) if controller.uses_feedback else _OneAhead(controller, setpoints))
    if closed_loop:
        testbed.watch_tracker(feed.age_s)
    squared_errors: list[float] = []
    tension_n = None
    cycles = unanswered_cycles = 0
    gc.freeze()
    try:
        session.start_fault_clock()
        setpoint = commands.next_setpoint()
        while setpoint is not None:
            commands.hold_until_ready()      # before the poll: the tip logged in this row is from this cycle
            measurement = feed.poll(setpoint.t_s)
            try:
                command = commands.command(setpoint, measurement, tension_n)
            except TrackerLostError:
                testbed.report_tracker_loss(feed.age_s())
                testbed.cycle()          # carries the stop out and raises SafetyStop
                raise
            next_setpoint = commands.next_setpoint()
            sample = testbed.cycle(AxisTargets(tuple(command.tendon_mm), command.insertion_mm),
                                   meanwhile=commands.meanwhile)
            tension_n = np.asarray(sample.tendon_tension_n, dtype=float)
            tip = None if measurement is None else measurement.tip_mm
            if recorder is not None:
                recorder.write(sample, tip, setpoint.tip_mm)
            coverage.add(sample.t_s, tip is not None)
            if tip is not None:
                squared_errors.append(float(np.sum((tip - setpoint.tip_mm) ** 2)))
            cycles += 1
            unanswered_cycles += not all(sample.fresh)
            if on_cycle is not None:
                on_cycle(cycles)
            setpoint = next_setpoint
    finally:
        gc.unfreeze()
        commands.close()
        if closed_loop:
            testbed.watch_tracker(None)
    rms = float(np.sqrt(np.mean(squared_errors))) if squared_errors else None
    return RunResult(cycles, len(squared_errors), feed.frames, rms, recorder.path if recorder else None,
                     coverage, command_process, commands.held_cycles, unanswered_cycles)


def commands_in_own_process(session: Session, controller: Controller) -> bool:
    """Whether run_with_controller computes the commands in a process of their own by default: a
    controller without feedback, a SYNC period below COMMAND_PROCESS_BELOW_S, a real-time master."""
    return (not controller.uses_feedback and session.scheduling.priority > 0
            and session.config.sync.period_s < COMMAND_PROCESS_BELOW_S)


class _InLoop:
    """Each command computed in the cycle that sends it, from what was measured (a controller with
    feedback)."""

    meanwhile = None
    held_cycles = 0

    def __init__(self, controller: Controller, setpoints: Iterable[SetPoint]) -> None:
        self._controller = controller
        self._upcoming = iter(setpoints)

    def next_setpoint(self) -> SetPoint | None:
        return next(self._upcoming, None)

    def hold_until_ready(self) -> None:
        """Keep the testbed cycling until the next command can be had at once (here it always can)."""

    def command(self, setpoint: SetPoint, measurement, tension_n) -> TendonCommand:
        return self._controller.command(setpoint, measurement, drive_tension_n=tension_n)

    def close(self) -> None:
        pass


class _OneAhead(_InLoop):
    """The command for the next set-point of a controller without feedback, computed as the cycle's
    ``meanwhile`` (while the drives answer this SYNC)."""

    def __init__(self, controller: Controller, setpoints: Iterable[SetPoint]) -> None:
        super().__init__(controller, setpoints)
        self.meanwhile: _CommandAhead | None = None
        self._following = next(self._upcoming, None)

    def next_setpoint(self) -> SetPoint | None:
        setpoint, self._following = self._following, next(self._upcoming, None)
        return setpoint

    def command(self, setpoint: SetPoint, measurement, tension_n) -> TendonCommand:
        command = self._controller.command(setpoint) if self.meanwhile is None else self.meanwhile.result()
        self.meanwhile = None if self._following is None else _CommandAhead(self._controller, self._following)
        return command


class _FromProcess(_InLoop):
    """The commands of a controller without feedback from a CommandProcess, the set-points sent to it
    `lead` ahead and topped up TOP_UP at a time. The run starts once the worker has answered the
    first `lead` (its start, a second or so, and its first calls, which load the model's compiled
    kernels); whenever the next command is not back (a worker that fell behind) the testbed holds its
    commands, cycle by cycle, without a row: the host heartbeat comes from the cycle. `held_cycles`
    counts the cycles held once the run has started."""

    TOP_UP = 16

    def __init__(self, controller: Controller, setpoints: Iterable[SetPoint], testbed: Testbed,
                 insertion_mm: float) -> None:
        super().__init__(controller, setpoints)
        self._testbed = testbed
        self._process = CommandProcess(controller, insertion_mm)
        self._queued: deque[SetPoint] = deque()
        self.held_cycles = 0
        try:
            self._top_up()
            self._hold_until(len(self._queued))
        except BaseException:
            self._process.close()
            raise

    def next_setpoint(self) -> SetPoint | None:
        if self._process.room >= self.TOP_UP:
            self._top_up()
        return self._queued.popleft() if self._queued else None

    def _top_up(self) -> None:
        fresh = list(islice(self._upcoming, self._process.room))
        self._process.submit(fresh)
        self._queued.extend(fresh)

    def _hold_until(self, count: int) -> int:
        """Hold the testbed until `count` commands are back (or an error ends the answers); the cycles held."""
        held = 0
        while self._process.ready() < count and not self._process.stopped_at_error:
            self._testbed.cycle()
            held += 1
        return held

    def hold_until_ready(self) -> None:
        self.held_cycles += self._hold_until(1)

    def command(self, setpoint: SetPoint, measurement, tension_n) -> TendonCommand:
        return self._process.next_command()

    def close(self) -> None:
        self._process.close()


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
