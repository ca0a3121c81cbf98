"""The supervised control cycle: every SYNC cycle is checked, and a stop is carried through.

After each SYNC cycle (``SyncCycle.run``) the runner checks, in this order: the drives'
heartbeats, each fresh TPDO1 (``feedback_fault``), and the tip tracker during a closed-loop
run. A problem trips the safety monitor, which quick-stops every axis before the next SYNC.
Whatever tripped it (these checks, an EMCY or error frame from the notifier, an exception in
a driver call), the cycle thread then finishes the stop (``finish_stop``): it keeps cycling
until no axis is energised (the quick stop ramp), disables every axis, runs the stop callbacks
(which flush the log) and raises SafetyStop, now and on every later call.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import can

from crest.config import TestbedConfig
from crest.driver import cia402, stop_requests
from crest.driver.cia402 import Cia402State, OperationMode
from crest.driver.clock import Clock
from crest.driver.drive_axis import DriveAxis
from crest.driver.errors import DriveError, DriveTimeout, SafetyStop
from crest.driver.feedback_checks import feedback_fault
from crest.driver.heartbeat_consumer import HeartbeatConsumer
from crest.driver.safety_monitor import SafetyMonitor
from crest.driver.stop_causes import exception_cause, heartbeat_cause, tracker_cause
from crest.driver.sync_cycle import SyncCycle


@dataclass(frozen=True)
class CycleSample:
    """One SYNC cycle, every tuple in AXIS_ORDER (tendon1..tendon4, insertion).

    ``target_mm`` is the set-point sent before this SYNC (the drives latch it at the SYNC);
    ``position_mm`` and ``tension_n`` were sampled by the drives at this SYNC, so they show
    the motion toward the previous set-point. ``fresh`` is False for an axis whose TPDO1 did not
    arrive (its values are the last ones received). ``limited`` says which streamed set-points
    the host clamped into the axis limits.
    """

    t_s: float
    target_mm: tuple[float, ...]
    position_mm: tuple[float, ...]
    tension_n: tuple[float, ...]
    states: tuple[Cia402State, ...]
    fresh: tuple[bool, ...]
    limited: tuple[str, ...] = ()

    @property
    def tendon_target_mm(self) -> tuple[float, ...]:
        return self.target_mm[:4]

    @property
    def insertion_target_mm(self) -> float:
        return self.target_mm[4]

    @property
    def tendon_position_mm(self) -> tuple[float, ...]:
        return self.position_mm[:4]

    @property
    def insertion_position_mm(self) -> float:
        return self.position_mm[4]

    @property
    def tendon_tension_n(self) -> tuple[float, ...]:
        return self.tension_n[:4]


class CycleRunner:
    """Runs supervised cycles for ``axes`` (in AXIS_ORDER) and owns the stop sequence."""

    def __init__(self, sync: SyncCycle, monitor: SafetyMonitor, heartbeats: HeartbeatConsumer,
                 axes: Sequence[DriveAxis], config: TestbedConfig, clock: Clock) -> None:
        self.sync = sync
        self.monitor = monitor
        self.heartbeats = heartbeats
        self.axes = tuple(axes)
        self.config = config
        self.clock = clock
        self.tracker_age_s: Callable[[], float | None] | None = None
        self.stop_callbacks: list[Callable[[SafetyStop], None]] = []
        self.safety_stop: SafetyStop | None = None
        self.last_sample: CycleSample | None = None
        self.cycle_observers: list[Callable[[CycleSample], None]] = []
        self._ramp_time_s = max(axis.config.max_velocity_mm_s / axis.config.max_acceleration_mm_s2
                                for axis in self.axes)

    # --- cycles ------------------------------------------------------------------------------
    def cycle(self, limited: Sequence[str] = (), meanwhile: Callable[[], None] | None = None) -> CycleSample:
        """One supervised SYNC cycle (``meanwhile``: see SyncCycle.run); SafetyStop if the testbed
        is (or gets) stopped. Its start is the safe point where a Ctrl-C or SIGTERM is raised
        (stop_requests), and from there the driver call stops every axis."""
        self.raise_if_stopped()
        stop_requests.raise_requested()
        latched = [axis.sent_target_counts if axis.mode is OperationMode.CYCLIC_SYNC_POSITION else None
                   for axis in self.axes]
        now_s, fresh = self.sync.run(meanwhile)
        if self.monitor.armed:
            self._check(now_s, fresh, latched)
        self.raise_if_stopped()
        self.last_sample = CycleSample(
            t_s=now_s,
            target_mm=tuple(axis.config.counts_to_mm(axis.sent_target_counts) for axis in self.axes),
            position_mm=tuple(axis.position_mm for axis in self.axes),
            tension_n=tuple(axis.tension_n for axis in self.axes),
            states=tuple(axis.state for axis in self.axes),
            fresh=fresh,
            limited=tuple(limited),
        )
        for observe in self.cycle_observers:
            observe(self.last_sample)
        return self.last_sample

    def _check(self, now_s: float, fresh: tuple[bool, ...], latched: list[int | None]) -> None:
        if self.heartbeats.silent_axes(now_s):
            self.monitor.trip(heartbeat_cause(self.heartbeats.silent_axes(now_s, self.heartbeats.timeout_s / 2.0),
                                              self.heartbeats.timeout_s))
        for axis, is_fresh, latched_counts in zip(self.axes, fresh, latched):
            if is_fresh:
                cause = feedback_fault(axis, latched_counts)
                if cause is not None:
                    self.monitor.trip(cause)
        if self.tracker_age_s is not None:
            age_s = self.tracker_age_s()
            limit_s = self.config.tracker.loss_timeout_s
            if age_s is None or age_s > limit_s:
                self.monitor.trip(tracker_cause(float("inf") if age_s is None else age_s, limit_s))

    def run_until(self, axes: Sequence[DriveAxis], reached: Callable[[DriveAxis], bool], step: str,
                  timeout_s: float | Mapping[str, float], *,
                  failed: Callable[[DriveAxis], DriveError | None] | None = None,
                  before_cycle: Callable[[list[DriveAxis]], None] | None = None) -> None:
        """Cycle until ``reached`` holds for every axis; each axis has its own time limit.

        The limit counts the drives' time: the shorter of the time passed and the SYNC periods
        sent since the start, min(t - t0, (k - k0) * T). A drive's motion advances one
        communication cycle per SYNC (the simulated drives' in every mode), so a host that sends
        its SYNCs late gives its drives less time to get there, and that is not the drive's fault:
        on a busy host a move that takes twice its planned time in wall time is still on time.
        ``before_cycle(pending)`` may update the commands of the axes not there yet;
        ``failed(axis)`` returns an error to raise at once. DriveTimeout names the axis,
        the step, its state and statusword.
        """
        start_s, start_syncs = self.clock.now_s(), self.sync.count
        limits = {axis.name: timeout_s[axis.name] if isinstance(timeout_s, Mapping) else timeout_s for axis in axes}
        pending = list(axes)
        while pending:
            if before_cycle is not None:
                before_cycle(pending)
            self.cycle()
            for axis in pending:
                error = failed(axis) if failed is not None else None
                if error is not None:
                    raise error
            pending = [axis for axis in pending if not reached(axis)]
            elapsed_s = min(self.clock.now_s() - start_s, (self.sync.count - start_syncs) * self.sync.period_s)
            for axis in pending:
                if elapsed_s > limits[axis.name]:
                    raise DriveTimeout(axis.name, f"{step}: not done within {limits[axis.name]:g} s "
                                                  f"(state {axis.state}, statusword 0x{axis.statusword:04X}); "
                                                  "check the drive and its wiring")

    # --- stopping ----------------------------------------------------------------------------
    def raise_if_stopped(self) -> None:
        if self.monitor.cause is not None:
            raise self.finish_stop()

    def trip_and_stop(self, error: BaseException) -> SafetyStop:
        """Stop for an exception raised by a driver call or the caller's loop."""
        self.monitor.trip(exception_cause(error))
        return self.finish_stop()

    def finish_stop(self) -> SafetyStop:
        """Complete the stop once (module docstring); returns the SafetyStop to raise."""
        if self.safety_stop is not None:
            return self.safety_stop
        cause = self.monitor.cause
        self.monitor.armed = False
        for axis in self.axes:
            axis.must_be_enabled = False
        notes = []
        if self.sync.started:
            try:
                self._ramp_down()
                self.sync.override(cia402.DISABLE_VOLTAGE)
                self.sync.run()
            except can.CanError as error:
                notes.append(f"the stop could not be completed on the bus ({error}); the drives stop "
                             "themselves when the host heartbeat stays away")
        notes += self.sync.send_failures
        stop = SafetyStop(cause)
        for note in notes:
            stop.add_note(note)
        self.safety_stop = stop
        for callback in self.stop_callbacks:
            try:
                callback(stop)
            except Exception as error:  # a failing log must not hide the stop itself
                stop.add_note(f"stop callback {getattr(callback, '__qualname__', callback)} failed: {error!r}")
        return stop

    def _ramp_down(self) -> None:
        """Cycle (quick stop in every RPDO) until no answering axis is energised, or the ramp time is over."""
        deadline_s = self.clock.now_s() + self._ramp_time_s + 3 * self.sync.period_s
        while self.clock.now_s() < deadline_s:
            _, fresh = self.sync.run()
            if not any(is_fresh and axis.state in cia402.ENERGISED_STATES for axis, is_fresh in zip(self.axes, fresh)):
                return
