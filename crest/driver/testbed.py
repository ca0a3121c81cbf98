"""The five axes of the CREST testbed as one machine: boot, home, move, jog, stream, stop.

The testbed talks to an opened ``can.BusABC``; whether that is hardware or the virtual testbed
is decided where the bus is opened. Typical use:

    with Testbed(bus, config) as testbed:   # any exception inside: safety stop, then SafetyStop
        testbed.on_safety_stop(lambda stop: log.close())
        testbed.boot()
        testbed.home()
        testbed.move_to(testbed.targets_from_pulls(2.0, 0.0, 40.0))
        for targets in trajectory:           # one SYNC cycle each, cyclic synchronous position
            sample = testbed.cycle(targets)

Every public call that commands the drives is guarded: Ctrl-C, a driver error, a CAN error or
any other exception trips the safety monitor (every axis quick-stops at once), the stop is
completed, and SafetyStop is raised from the original exception. MotionRefused is the one
exception that passes through without a stop: it is raised before anything moved.

Host-side limits: point-move and trajectory targets outside the soft limits, or trajectories
faster than max velocity / acceleration, are refused; set-points streamed with ``cycle`` are
clamped and the sample says so (motion_limits.py).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass

import can
import canopen

from crest.config import TestbedConfig
from crest.driver import cia402, homing, profile_position, state_control
from crest.driver.answer_latency import AnswerLatency
from crest.driver.axis_targets import AXIS_ORDER, AxisTargets
from crest.driver.boot import reset_and_configure
from crest.driver.cia402 import Cia402State, OperationMode
from crest.driver.clock import Clock, MonotonicClock, SteppedClock
from crest.driver.cycle_runner import CycleRunner, CycleSample
from crest.driver.drive_axis import ERROR_CODE, FOLLOWING_ERROR_ACTUAL, POSITION_ACTUAL, STATUSWORD, DriveAxis
from crest.driver.drive_parameters import CONSUMER_HEARTBEAT_TIME
from crest.driver.errors import DriveError, MotionRefused, SafetyStop
from crest.driver.heartbeat_consumer import HeartbeatConsumer
from crest.driver.heartbeat_producer import HeartbeatProducer
from crest.driver.identity import DriveIdentity
from crest.driver.motion_limits import SetPointLimiter, check_positions, check_trajectory
from crest.driver.safety_monitor import ErrorFrameListener, SafetyMonitor
from crest.driver.stop_causes import emcy_text, operator_cause, tracker_cause
from crest.driver.sync_cycle import SyncCycle
from crest.driver.sync_timing import SyncTiming
from crest.driver.synchronized_move import AxisProfile, synchronized_move

NMT_START = 0x01
NMT_ENTER_PRE_OPERATIONAL = 0x80
#: Shortest wall time to wait for the TPDOs after a SYNC (the longer of this and two periods).
MIN_REPLY_TIMEOUT_S = 0.02
#: In simulated time, wall time to wait for a SYNC's first TPDO, and for the others once one came:
#: the drives answer late only when a host is busy (a loaded 2-core machine delayed replies, and the
#: gaps between them, past 20 ms across the process boundary). A silent drive costs each cycle the
#: second, until its heartbeat is lost (0.25 s of simulated time: about 6 s of wall time at 100 Hz).
SIMULATED_TIME_FIRST_REPLY_TIMEOUT_S = 2.0
SIMULATED_TIME_REPLY_TIMEOUT_S = 0.25
#: Longest the CAN receive thread blocks before it looks whether it should end (close waits for it).
RECEIVE_POLL_S = 0.1


@dataclass(frozen=True)
class BootReport:
    duration_s: float                       # wall time the boot took
    identities: dict[str, DriveIdentity]


@dataclass(frozen=True)
class AxisStatus:
    """One row of ``crest status``; read by SDO, the NMT state from the last heartbeat."""

    axis: str
    node_id: int
    nmt_state: str
    state: Cia402State
    position_mm: float
    following_error_mm: float
    error_code: int

    @property
    def fault(self) -> str:
        """'' or the active error code with its meaning."""
        return emcy_text(self.error_code) if self.error_code else ""


class Testbed:
    """The CREST testbed on ``bus``, configured by ``config``; ``clock`` paces SYNC (wall time by default)."""

    __test__ = False  # not a pytest test class despite the name

    def __init__(self, bus: can.BusABC, config: TestbedConfig, *, clock: Clock | None = None) -> None:
        self.config = config
        self.clock = clock if clock is not None else MonotonicClock()
        self._network = canopen.Network(bus)
        self._network.NOTIFIER_CYCLE = RECEIVE_POLL_S
        feedback_changed = threading.Condition()
        self.axes: dict[str, DriveAxis] = {}
        for name in AXIS_ORDER:
            axis_config = config.axis(name)
            node = canopen.RemoteNode(axis_config.node_id, str(axis_config.eds_path))
            self._network.add_node(node)
            axis = DriveAxis(axis_config, node, config.master.sdo_timeout_s, feedback_changed)
            self._network.subscribe(axis.tpdo_cob_id, axis.on_tpdo)
            self.axes[name] = axis
        self._axis_list = tuple(self.axes.values())
        self._heartbeats = HeartbeatConsumer(self._network, self.clock,
                                             {axis.config.node_id: axis.name for axis in self._axis_list},
                                             config.master.heartbeat_timeout_s)
        period_s = config.sync.period_s
        sync = SyncCycle(self._network, self.clock, self._axis_list, period_s,
                         HeartbeatProducer(self._network, config.master.node_id, config.master.heartbeat_period_s),
                         feedback_changed, **_reply_timeouts(self.clock, period_s))
        self._monitor = SafetyMonitor(sync.quick_stop_all)
        for axis in self._axis_list:
            axis.node.emcy.add_callback(self._monitor.emcy_listener(axis.name))
        self._network.listeners.append(ErrorFrameListener(self._monitor))
        self._runner = CycleRunner(sync, self._monitor, self._heartbeats, self._axis_list, config, self.clock)
        self._limiters = {axis.name: SetPointLimiter(axis.config, period_s, 0.0) for axis in self._axis_list}

    # --- life cycle ------------------------------------------------------------------------
    def connect(self) -> None:
        """Start listening on the bus (boot does this; ``status`` works after it alone)."""
        if self._network.notifier is None:
            self._network.connect()

    def boot(self) -> BootReport:
        """The boot sequence: boot.py's SDO part, then host heartbeat, NMT start, SYNC, first TPDOs.

        Raises a DriveError naming the axis and the step (nothing is enabled yet).
        """
        started_s = time.monotonic()
        self.connect()
        identities = reset_and_configure(self._axis_list, self._heartbeats, self.config)
        self._heartbeats.start_watching()
        for axis in self._axis_list:
            axis.node.nmt.send_command(NMT_START)
        self._runner.run_until(self._axis_list, lambda axis: axis.tpdo_count > 0, "first TPDO1 after NMT start",
                               self.config.master.boot_timeout_s)
        self._monitor.armed = True
        return BootReport(duration_s=time.monotonic() - started_s, identities=identities)

    def close(self) -> None:
        """Orderly end: disable every axis, stop the drives watching the host, NMT pre-operational.

        After a safety stop only the listening ends (the drives were stopped already; they fault
        on the missing host heartbeat, which the next boot's NMT reset clears). The bus itself
        is left open for its owner.
        """
        if self._network.notifier is None:
            return
        try:
            if self._runner.sync.started and self._runner.safety_stop is None:
                with self._guarded():
                    state_control.disable(self._runner, self._axis_list)
                    self._monitor.armed = False
                    self._heartbeats.stop_watching()
                    for axis in self._axis_list:
                        axis.sdo.write(CONSUMER_HEARTBEAT_TIME, 1, 0, "closing: stop watching the host heartbeat")
                        axis.node.nmt.send_command(NMT_ENTER_PRE_OPERATIONAL)
        finally:
            self._network.notifier.stop()
            self._network.notifier = None

    def __enter__(self) -> Testbed:
        return self

    def __exit__(self, exc_type, exc_value, traceback) -> None:
        """Ctrl-C or an exception in the block: safety stop, then SafetyStop from it; else close."""
        if isinstance(exc_value, (Exception, KeyboardInterrupt)) and not isinstance(exc_value, SafetyStop):
            stop = self._runner.trip_and_stop(exc_value)
            self.close()
            raise stop from exc_value
        self.close()

    # --- safety ------------------------------------------------------------------------------
    def on_safety_stop(self, callback: Callable[[SafetyStop], None]) -> None:
        """Call ``callback(stop)`` once the axes are stopped (e.g. flush and close the log)."""
        self._runner.stop_callbacks.append(callback)

    def report_tracker_loss(self, age_s: float) -> None:
        """Tracker loss in a closed-loop run (any thread): quick-stop now; the next call raises SafetyStop."""
        self._monitor.trip(tracker_cause(age_s, self.config.tracker.loss_timeout_s))

    def operator_stop(self, reason: str) -> None:
        """An operator's stop from any thread (the live view's E-STOP): every axis quick-stops now,
        and the loop's next call finishes the stop like Ctrl-C does (exit code INTERRUPTED, ``reason``)."""
        self._monitor.trip(operator_cause(reason))

    def observe_cycles(self, observer: Callable[[CycleSample], None]) -> None:
        """Hand every supervised cycle's sample to ``observer``, in the control loop's thread.

        The observer must return at once: no I/O, no lock held by another thread for long
        (the live view appends to a bounded deque and does its work in its own thread).
        """
        self._runner.cycle_observers.append(observer)

    def watch_tracker(self, sample_age_s: Callable[[], float | None] | None) -> None:
        """Check every cycle that ``sample_age_s()`` (s since the last valid tip sample, None: none
        yet) stays within tracker.loss_timeout_s; None ends the watch (the closed-loop run is over)."""
        self._runner.tracker_age_s = sample_age_s

    @property
    def safety_stop(self) -> SafetyStop | None:
        """The stop, once the testbed has been stopped."""
        return self._runner.safety_stop

    @property
    def answer_latency(self) -> AnswerLatency:
        """How long the drives' answers to each SYNC took, in wall time (crest.driver.answer_latency)."""
        return self._runner.sync.answer_latency

    @property
    def sync_timing(self) -> SyncTiming:
        """When each SYNC left, as the master times them (crest.driver.sync_timing)."""
        return self._runner.sync.timing

    @contextmanager
    def _guarded(self) -> Iterator[None]:
        try:
            yield
        except (SafetyStop, MotionRefused):
            raise
        except (Exception, KeyboardInterrupt) as error:
            raise self._runner.trip_and_stop(error) from error

    # --- commands ------------------------------------------------------------------------------
    def enable(self) -> None:
        """Every axis to OPERATION ENABLED in profile position mode, halted where it stands."""
        with self._guarded():
            self._require_booted()
            state_control.enable(self._runner, self._axis_list)

    def home(self) -> None:
        """Home every axis with its method, then pull every tendon to the pretension (pulls 0, 0)."""
        with self._guarded():
            self._ensure_enabled()
            homing.home(self._runner, self._axis_list)
            insertion_mm = self.axes[AXIS_ORDER[4]].position_mm
            self._move(self.targets_from_pulls(0.0, 0.0, insertion_mm), speed_fraction=1.0)

    def move_to(self, targets: AxisTargets, *, speed_fraction: float = 1.0) -> CycleSample:
        """Profile-position move of all five axes, synchronized (synchronized_move.py); blocks until reached.

        ``speed_fraction`` (0, 1] scales max velocity and acceleration. Targets outside the soft
        limits are refused (MotionRefused) before anything moves. Returns the last cycle.
        """
        with self._guarded():
            check_positions(self.config, targets)
            self._check_fraction(speed_fraction)
            self._ensure_enabled()
            return self._move(targets, speed_fraction)

    def jog_to(self, targets: AxisTargets, *, speed_fraction: float = 0.25) -> CycleSample:
        """Hand over new profile-position targets (change set immediately) and return without waiting.

        Call ``cycle()`` to let the motion run; a later ``jog_to`` replaces the target on the way.
        """
        with self._guarded():
            check_positions(self.config, targets, what="jog target")
            self._check_fraction(speed_fraction)
            self._ensure_enabled()
            state_control.switch_mode(self._runner, self._axis_list, OperationMode.PROFILE_POSITION)
            self._hand_over(targets, speed_fraction)
            return self._runner.last_sample

    def cycle(self, targets: AxisTargets | None = None, *,
              meanwhile: Callable[[], None] | None = None) -> CycleSample:
        """One SYNC cycle. With ``targets``: cyclic synchronous position set-points (clamped into
        the limits, see CycleSample.limited); without: the axes keep their current command.
        ``meanwhile`` runs once the SYNC is sent, while the drives answer it."""
        with self._guarded():
            if targets is None:
                return self._runner.cycle(meanwhile=meanwhile)
            return self._stream(targets, meanwhile)

    def hold(self, duration_s: float) -> CycleSample:
        """Keep cycling for ``duration_s`` (clock time) with the current commands.

        Heartbeat and SYNC come from the cycle, so a caller that waits (for a key, a user, a
        plot) must keep calling ``cycle`` or ``hold``: the drives stop themselves when the host
        is silent for heartbeat_timeout_s.
        """
        with self._guarded():
            self._require_booted()
            end_s = self.clock.now_s() + duration_s
            sample = self._runner.cycle()
            while self.clock.now_s() < end_s:
                sample = self._runner.cycle()
            return sample

    def run_trajectory(self, samples: Sequence[AxisTargets],
                       on_sample: Callable[[CycleSample], None] | None = None) -> list[CycleSample]:
        """Check a trajectory (one sample per SYNC period) against every limit, move to its first
        sample, then stream it in cyclic synchronous position mode; ``on_sample`` sees every cycle."""
        with self._guarded():
            check_trajectory(self.config, samples)
            self._ensure_enabled()
            self._move(samples[0], speed_fraction=1.0)
            cycles = []
            for targets in samples:
                sample = self._stream(targets)
                cycles.append(sample)
                if on_sample is not None:
                    on_sample(sample)
            return cycles

    def status(self) -> tuple[AxisStatus, ...]:
        """Every axis' NMT state, CiA 402 state, position, following error and error code (by SDO)."""
        with self._guarded():
            self.connect()
            rows = []
            for axis in self._axis_list:
                read = axis.sdo.read
                statusword = read(STATUSWORD, 0, "status")
                position_counts = read(POSITION_ACTUAL, 0, "status")
                following_error_counts = read(FOLLOWING_ERROR_ACTUAL, 0, "status")
                error_code = read(ERROR_CODE, 0, "status")
                rows.append(AxisStatus(  # NMT state last: the SDO replies came after any earlier heartbeat
                    axis=axis.name, node_id=axis.config.node_id, nmt_state=self._heartbeats.nmt_state(axis.name),
                    state=cia402.state_from_statusword(statusword),
                    position_mm=axis.config.counts_to_mm(position_counts),
                    following_error_mm=axis.config.counts_to_mm(following_error_counts), error_code=error_code))
            return tuple(rows)

    # --- set-points ------------------------------------------------------------------------------
    def targets_from_pulls(self, pull_13_mm: float, pull_24_mm: float, insertion_mm: float) -> AxisTargets:
        """Set-points for two differential tendon pulls around the configured pretension."""
        return AxisTargets.from_pulls(pull_13_mm, pull_24_mm, insertion_mm, self.config.coordination.pretension_mm)

    def commanded(self) -> AxisTargets:
        """The set-points currently commanded (profile position target or last streamed set-point)."""
        return AxisTargets.from_axis_values(tuple(axis.target_mm for axis in self._axis_list))

    def positions(self) -> AxisTargets:
        """The position actual of every axis from the last TPDO1."""
        return AxisTargets.from_axis_values(tuple(axis.position_mm for axis in self._axis_list))

    # --- internals ------------------------------------------------------------------------------
    def _require_booted(self) -> None:
        if not self._runner.sync.started or self._network.notifier is None:
            raise DriveError(None, "the testbed is not booted (or was closed); call boot() first")

    def _ensure_enabled(self) -> None:
        self._require_booted()
        if not all(axis.must_be_enabled for axis in self._axis_list):
            state_control.enable(self._runner, self._axis_list)

    @staticmethod
    def _check_fraction(speed_fraction: float) -> None:
        if not 0.0 < speed_fraction <= 1.0:
            raise MotionRefused(None, f"speed_fraction {speed_fraction!r} must be in (0, 1]; nothing was moved")

    def _hand_over(self, targets: AxisTargets, speed_fraction: float) -> float:
        """Synchronized profiles and set-points for the axes whose target changes; returns the duration."""
        goals = dict(zip(AXIS_ORDER, targets.values()))
        move = synchronized_move([goals[axis.name] - axis.target_mm for axis in self._axis_list],
                                 [axis.config.max_velocity_mm_s * speed_fraction for axis in self._axis_list],
                                 [axis.config.max_acceleration_mm_s2 * speed_fraction for axis in self._axis_list])
        moving: dict[str, int] = {}
        for axis, profile in zip(self._axis_list, move.profiles):
            goal_counts = axis.config.mm_to_counts(goals[axis.name])
            if goal_counts != axis.target_counts:
                profile_position.set_profile(axis, AxisProfile(profile.velocity_mm_s, profile.acceleration_mm_s2))
                moving[axis.name] = goal_counts
        if moving:
            profile_position.hand_over(self._runner, moving, self._axis_list)
        return move.duration_s

    def _move(self, targets: AxisTargets, speed_fraction: float) -> CycleSample:
        state_control.switch_mode(self._runner, self._axis_list, OperationMode.PROFILE_POSITION)
        duration_s = self._hand_over(targets, speed_fraction)
        profile_position.wait_reached(self._runner, self._axis_list, duration_s)
        return self._runner.last_sample

    def _stream(self, targets: AxisTargets, meanwhile: Callable[[], None] | None = None) -> CycleSample:
        self._ensure_enabled()
        if any(axis.mode is not OperationMode.CYCLIC_SYNC_POSITION for axis in self._axis_list):
            state_control.switch_mode(self._runner, self._axis_list, OperationMode.CYCLIC_SYNC_POSITION)
            for axis in self._axis_list:
                self._limiters[axis.name].reset(axis.target_mm)
        limited = []
        for axis, requested_mm in zip(self._axis_list, targets.values()):
            set_point_mm, message = self._limiters[axis.name].limit(requested_mm)
            if message is not None:
                limited.append(message)
            axis.target_counts = axis.config.mm_to_counts(set_point_mm)
            axis.command(cia402.ENABLE_OPERATION, halt=False)
        return self._runner.cycle(limited, meanwhile)


def _reply_timeouts(clock: Clock, period_s: float) -> dict[str, float]:
    """SyncCycle's wall-time patience for the TPDOs: in real time two periods (at least
    MIN_REPLY_TIMEOUT_S), in simulated time the SIMULATED_TIME_* values."""
    if isinstance(clock, SteppedClock):
        return {"reply_timeout_s": SIMULATED_TIME_REPLY_TIMEOUT_S,
                "first_reply_timeout_s": SIMULATED_TIME_FIRST_REPLY_TIMEOUT_S}
    return {"reply_timeout_s": max(2.0 * period_s, MIN_REPLY_TIMEOUT_S)}
