"""A simulated CiA 402 servo amplifier, as a node on a canopen.Network.

On the wire it behaves like a real drive: boot-up message and NMT states, an SDO
server on 0x600/0x580 + node id, TPDOs on SYNC and RPDOs into the object
dictionary, the CiA 402 state machine on the controlword, profile position,
homing and cyclic synchronous position modes, software position limits
(0x607D), a following-error monitor (0x6065/0x6066), a heartbeat producer
(0x1017) and a heartbeat consumer (0x1016) watching the master, and EMCY
messages with CiA 301/402 error codes and the error register 0x1001.

Two clocks, neither of them read here:
- motion advances by one communication cycle (0x1006, else the spec's cycle
  period) per received SYNC frame, in every NMT state (the frame is the
  simulation's clock; only PDO traffic depends on OPERATIONAL);
- heartbeat production, the heartbeat-consumer timeout and injected faults run
  on ``tick(now_s)``, called with an injected time (tests) or wall time (the
  real-time runner).

Positions: the motor's own position (``ServoAxis``, counts) is the plant's frame
scaled by counts_per_mm. The drive reports position actual 0x6064 = motor
position + position offset, where homing sets the offset; targets and limits
written in the drive's counts are converted back by subtracting the offset.

Fault reaction: the drive disables the power stage at once and the holding
brake stops the motor (fault reaction option "disable drive function"), so
FAULT REACTION ACTIVE (transition 13) is followed by FAULT (14) in the same step.

All entry points (bus callbacks from the network's notifier thread, ``tick``
from the runner, the plant's setters) take the drive's lock.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

import can
import canopen
from canopen.pdo import PdoMap
from canopen.sdo import SdoAbortedError

from sim_backend.drive import emergency
from sim_backend.drive.can_error_counter import CanErrorCounter
from sim_backend.drive.cia402_state_machine import Cia402StateMachine, DriveState
from sim_backend.drive.cyclic_sync_position import FOLLOWS_COMMAND_BIT, latch_set_point
from sim_backend.drive.drive_node import DriveNode
from sim_backend.drive.drive_spec import DriveSpec
from sim_backend.drive.emergency import ActiveErrors
from sim_backend.drive.heartbeat_consumer import HeartbeatConsumer
from sim_backend.drive.homing import HALT_BIT as HOMING_HALT_BIT
from sim_backend.drive.homing import SUPPORTED_METHODS, Homing, HomingParameters
from sim_backend.drive.nmt_slave import OPERATIONAL, RESET_NODE, STOPPED
from sim_backend.drive.process_data import ProcessData, is_pdo_parameter
from sim_backend.drive.profile_position import RELATIVE_BIT, MotionProfile, ProfilePosition
from sim_backend.drive.servo_axis import ServoAxis
from sim_backend.drive.setpoint_generator import SetpointGenerator
from sim_backend.faults import FaultKind

T = TypeVar("T")

MODE_NONE = 0
MODE_PROFILE_POSITION = 1
MODE_HOMING = 6
MODE_CYCLIC_SYNC_POSITION = 8
SUPPORTED_MODES = frozenset({MODE_NONE, MODE_PROFILE_POSITION, MODE_HOMING, MODE_CYCLIC_SYNC_POSITION})

WARNING_BIT = 0x0080
REMOTE_BIT = 0x0200
INTERNAL_LIMIT_BIT = 0x0800
FOLLOWING_ERROR_BIT = 0x2000
FOLLOWING_ERROR_CHECK_OFF = 0xFFFFFFFF

SYNC_COB_ID = 0x80
ABORT_VALUE_RANGE = 0x06090030
ENERGISED_STATES = frozenset({DriveState.OPERATION_ENABLED, DriveState.QUICK_STOP_ACTIVE})


class SimDrive:
    """One simulated servo amplifier. Create, ``attach`` to a network, then ``power_on``."""

    def __init__(self, spec: DriveSpec) -> None:
        self.spec = spec
        self._lock = threading.RLock()
        self.node = DriveNode(spec.node_id, str(Path(spec.eds_path)), on_written=self._on_written,
                              on_reset=self._on_nmt_reset, send=self._send)
        self.node.add_write_callback(self._validate_write)
        self._process_data = ProcessData(self.node, send=self._send, on_rpdo=self._on_rpdo,
                                         on_length_error=self._on_pdo_length_error)
        self._servo = ServoAxis(spec.to_counts(spec.max_velocity_mm_s * spec.motor_velocity_reserve),
                                spec.to_counts(spec.max_acceleration_mm_s2 * spec.motor_acceleration_reserve),
                                position_counts=spec.to_counts(spec.start_position_mm))
        self._demand = SetpointGenerator(self._servo.position_counts)
        self._state_machine = Cia402StateMachine()
        self._profile_position = ProfilePosition()
        self._homing = self._new_homing()
        self._consumer = HeartbeatConsumer()
        self._watched_cob_id: int | None = None
        self._errors = ActiveErrors()
        self._can_errors = CanErrorCounter()
        self._position_offset_counts = 0.0
        self._load_tension_n = 0.0
        self._internal_limit = False
        self._following_error_s = 0.0
        self._in_position_window_s = 0.0
        self._powered = False
        self.silent = False
        self.sdo_silent = False
        self.error_frames_active = False
        self._network: canopen.Network | None = None
        self._applying_rpdo = False   # publish once after an RPDO's objects, not after each (_on_written)

    # --- public face -----------------------------------------------------------------
    @property
    def name(self) -> str:
        return self.spec.name

    @property
    def node_id(self) -> int:
        return self.spec.node_id

    @property
    def position_actual_mm(self) -> float:
        """Motor (tendon / pulley) position in the plant's frame, mm; what the plant is stepped with."""
        with self._lock:
            return self._servo.position_counts / self.spec.counts_per_mm

    @property
    def state(self) -> DriveState:
        with self._lock:
            return self._state_machine.state

    @property
    def nmt_state(self) -> str:
        with self._lock:
            return self.node.nmt.state

    @property
    def statusword(self) -> int:
        with self._lock:
            return self.node.value(0x6041)

    @property
    def active_error_codes(self) -> tuple[int, ...]:
        with self._lock:
            return self._errors.codes

    def set_load_tension_n(self, tension_n: float) -> None:
        """The plant's tension on this axis; reported as torque actual 0x6077 from the next sample."""
        with self._lock:
            self._load_tension_n = tension_n

    def attach(self, network: canopen.Network) -> None:
        """Join a network: the node's SDO server, NMT slave and RPDOs, gated by this drive."""
        network.add_node(self.node)
        network.unsubscribe(self.node.sdo.rx_cobid, self.node.sdo.on_request)
        network.unsubscribe(0, self.node.nmt.on_command)
        network.subscribe(self.node.sdo.rx_cobid, self._on_sdo_request)
        network.subscribe(0, self._on_nmt_command)
        network.subscribe(SYNC_COB_ID, self._on_sync)
        self._network = network

    def power_on(self) -> None:
        """Switch the drive on: defaults loaded, boot-up message sent, PRE-OPERATIONAL."""
        with self._lock:
            self._powered = True
            self._restart_application()
            self._restart_communication()
            self._publish()
            self.node.nmt.boot_up()

    def tick(self, now_s: float) -> None:
        """Time-based duties at time ``now_s``: heartbeat production and the master's heartbeat watch."""
        with self._lock:
            if not self._powered:
                return
            self.node.nmt.tick(now_s)
            if self._consumer.tick(now_s):
                self._raise_fault(emergency.HEARTBEAT_ERROR)

    def inject_fault(self, kind: FaultKind) -> None:
        """Make this drive misbehave like a real one would (see sim_backend.faults)."""
        with self._lock:
            if kind is FaultKind.EMCY:
                self._raise_fault(emergency.OVER_CURRENT)
            elif kind is FaultKind.HEARTBEAT:
                self.silent = True
            elif kind is FaultKind.STALL:
                self._servo.stalled = True
            elif kind is FaultKind.SDO_TIMEOUT:
                self.sdo_silent = True
            elif kind is FaultKind.ERROR_FRAMES:
                self.error_frames_active = True
            else:
                raise ValueError(f"drive {self.name!r}: {kind.value!r} is a tracker fault, not a drive fault")

    # --- bus entry points --------------------------------------------------------------
    def _listening(self) -> bool:
        return self._powered and not self.silent

    def _on_sdo_request(self, can_id: int, data: bytearray, timestamp: float) -> None:
        with self._lock:
            if self._listening() and not self.sdo_silent and self.node.nmt.state_code != STOPPED:
                self.node.sdo.on_request(can_id, data, timestamp)

    def _on_nmt_command(self, can_id: int, data: bytearray, timestamp: float) -> None:
        with self._lock:
            if self._listening():
                self.node.nmt.on_command(can_id, data, timestamp)
                self._publish()

    def _on_master_heartbeat(self, can_id: int, data: bytearray, timestamp: float) -> None:
        with self._lock:
            if self._listening():
                self._consumer.on_heartbeat()

    def _on_rpdo(self, pdo_map: PdoMap) -> None:
        with self._lock:
            if self._listening() and self.node.nmt.state_code == OPERATIONAL:
                if self._unpublished(lambda: self._process_data.receive(pdo_map)):
                    self._publish()

    def _unpublished(self, apply_rpdos: Callable[[], T]) -> T:
        """`apply_rpdos()` (writes of RPDO objects) with `_on_written`'s publishing held back: the
        caller publishes once, after all of them."""
        self._applying_rpdo = True
        try:
            return apply_rpdos()
        finally:
            self._applying_rpdo = False

    def _on_sync(self, can_id: int, data: bytearray, timestamp: float) -> None:
        """CiA 301 SYNC: apply synchronous RPDOs, sample and send TPDOs, then run one cycle."""
        with self._lock:
            if not self._listening():
                return
            operational = self.node.nmt.state_code == OPERATIONAL
            if operational:
                self._unpublished(self._process_data.apply_synchronous_rpdos)
            self._publish()
            if operational:
                self._process_data.transmit_on_sync()
            if self.error_frames_active:
                self._send_error_frame()
            self._advance(self._cycle_period_s())
            self._publish()

    # --- transmission --------------------------------------------------------------------
    def _send(self, cob_id: int, data: bytes) -> None:
        """Transmit unless silent; in STOPPED only the NMT error-control (heartbeat) frame."""
        if self.silent or self._network is None:
            return
        if self.node.nmt.state_code == STOPPED and cob_id != 0x700 + self.node_id:
            return
        self._network.send_message(cob_id, data)
        self._can_errors.on_transmit_success()
        self._update_error_passive()

    def _emcy(self, error_code: int, register: int) -> None:
        if self.silent or self.node.nmt.state_code == STOPPED:
            return
        self.node.emcy.send(error_code, register)

    def _send_error_frame(self) -> None:
        """A transmission destroyed on the wire: error frame, TEC + 8 (until error passive)."""
        if self._can_errors.error_passive:
            self.error_frames_active = False
            return
        with self._network.send_lock:
            self._network.bus.send(can.Message(is_error_frame=True, arbitration_id=0, dlc=0))
        self._can_errors.on_transmit_error()
        self._update_error_passive()

    def _update_error_passive(self) -> None:
        active = emergency.CAN_ERROR_PASSIVE in self._errors.codes
        if self._can_errors.error_passive and not active:
            self._emcy(emergency.CAN_ERROR_PASSIVE, self._errors.raise_error(emergency.CAN_ERROR_PASSIVE))
        elif active and not self._can_errors.error_passive:
            self._emcy(emergency.NO_ERROR, self._errors.clear(emergency.CAN_ERROR_PASSIVE))

    def _on_pdo_length_error(self) -> None:
        register = self._errors.raise_error(emergency.PDO_LENGTH_ERROR)
        self._emcy(emergency.PDO_LENGTH_ERROR, register)
        self._errors.clear(emergency.PDO_LENGTH_ERROR)

    # --- object dictionary ---------------------------------------------------------------
    def _defaults(self) -> dict[tuple[int, int], int]:
        """Values the drive loads over the EDS defaults at boot: this axis' scaling and limits."""
        spec = self.spec
        counts = spec.to_counts
        low_mm, high_mm = spec.soft_limits_mm
        return {
            (0x1006, 0): round(spec.cycle_period_s * 1e6),
            (0x1016, 1): (spec.master_node_id << 16) | round(spec.heartbeat_timeout_s * 1000),
            (0x1017, 0): round(spec.heartbeat_period_s * 1000),
            (0x1018, 4): spec.node_id,
            (0x6065, 0): round(counts(spec.following_error_window_mm)),
            (0x6066, 0): round(spec.following_error_timeout_s * 1000),
            (0x6067, 0): round(counts(spec.position_window_mm)),
            (0x6076, 0): round(spec.rated_torque_mnm),
            (0x607C, 0): round(counts(spec.home_position_mm)),
            (0x607D, 1): round(counts(low_mm)),
            (0x607D, 2): round(counts(high_mm)),
            (0x6081, 0): round(counts(spec.max_velocity_mm_s)),
            (0x6083, 0): round(counts(spec.max_acceleration_mm_s2)),
            (0x6084, 0): round(counts(spec.max_acceleration_mm_s2)),
            (0x6085, 0): round(counts(spec.max_acceleration_mm_s2)),
            (0x6098, 0): spec.homing_method,
            (0x6099, 1): round(counts(spec.max_velocity_mm_s / 2.0)),
            (0x6099, 2): round(counts(spec.max_velocity_mm_s / 10.0)),
            (0x609A, 0): round(counts(spec.max_acceleration_mm_s2)),
        }

    def _restart_application(self) -> None:
        """Power-on / NMT reset node: application objects to defaults, SWITCH ON DISABLED, not homed."""
        for index in [index for index in self.node.data_store if index >= 0x2000]:
            del self.node.data_store[index]
        for (index, subindex), value in self._defaults().items():
            if index >= 0x2000:
                self.node.store(index, subindex, value)
        self._state_machine.power_up()
        self._servo.brake()
        self._demand.sync(self._servo.position_counts)
        self._position_offset_counts = 0.0
        self._profile_position.reset(self._demand.position_counts)
        self._homing = self._new_homing()
        self._errors = ActiveErrors()
        self._internal_limit = False
        self._following_error_s = 0.0

    def _restart_communication(self) -> None:
        """NMT reset communication: 0x1000-0x1FFF to defaults, PDOs and heartbeat reloaded."""
        for index in [index for index in self.node.data_store if index < 0x2000]:
            del self.node.data_store[index]
        for (index, subindex), value in self._defaults().items():
            if index < 0x2000:
                self.node.store(index, subindex, value)
        self.node.nmt.start_heartbeat(self.node.value(0x1017))
        self._process_data.load()
        self._watch_master()

    def _on_nmt_reset(self, command: int) -> None:
        if command == RESET_NODE:
            self._restart_application()
        self._restart_communication()
        self._publish()

    def _watch_master(self) -> None:
        """Subscribe to the heartbeat of the producer named in 0x1016:1."""
        self._consumer.configure(self.node.value(0x1016, 1))
        if self._watched_cob_id is not None:
            self._network.unsubscribe(self._watched_cob_id, self._on_master_heartbeat)
            self._watched_cob_id = None
        if self._consumer.enabled:
            self._watched_cob_id = 0x700 + self._consumer.producer_node_id
            self._network.subscribe(self._watched_cob_id, self._on_master_heartbeat)

    def _validate_write(self, index: int, subindex: int, od, data: bytes) -> None:
        """LocalNode write callback, before the value is stored: refuse what the drive cannot take."""
        self._process_data.validate_write(index, subindex, data)
        if index == 0x6060 and od.decode_raw(data) not in SUPPORTED_MODES:
            raise SdoAbortedError(ABORT_VALUE_RANGE)
        if index == 0x6098 and od.decode_raw(data) not in SUPPORTED_METHODS:
            raise SdoAbortedError(ABORT_VALUE_RANGE)
        if index == 0x605A and not 0 <= od.decode_raw(data) <= 8:
            raise SdoAbortedError(ABORT_VALUE_RANGE)

    def _on_written(self, index: int, subindex: int) -> None:
        """A value was stored by an SDO download or an RPDO. An SDO download's effect is published at
        once; an RPDO's once all its objects are written (`_on_rpdo`, and `_on_sync` for synchronous
        RPDOs): the same objects and event TPDOs as after each object, for a fraction of the work."""
        if index == 0x6040:
            self._on_controlword(self.node.value(0x6040))
        elif index == 0x6060:
            self._on_mode_written(self.node.value(0x6060))
        elif index == 0x1016:
            self._watch_master()
        elif is_pdo_parameter(index):
            self._process_data.on_config_written(index)
        if not self._applying_rpdo:
            self._publish()

    # --- CiA 402 ----------------------------------------------------------------------
    def _mode(self) -> int:
        return self.node.value(0x6061)

    def _on_mode_written(self, mode: int) -> None:
        self.node.store(0x6061, 0, mode)
        self._profile_position.reset(self._demand.position_counts)
        self._homing.interrupt()

    def _on_controlword(self, controlword: int) -> None:
        was = self._state_machine.state
        transitions = self._state_machine.on_controlword(controlword, self.node.value(0x605A))
        if 11 in transitions and self.node.value(0x605A) == 0:
            self._state_machine.on_quick_stop_done()  # option 0: disable drive function at once
        self._after_transitions(was)
        new_set_point = self._profile_position.on_controlword(controlword)
        start_homing = self._homing.on_controlword(controlword)
        if self._state_machine.state is not DriveState.OPERATION_ENABLED:
            return
        if self._mode() == MODE_PROFILE_POSITION and new_set_point:
            self._take_set_point(controlword)
        elif self._mode() == MODE_HOMING and start_homing:
            offset = self._homing.start(self._homing_parameters(), self._servo.position_counts)
            if offset is not None:
                self._set_position_offset(offset)

    def _after_transitions(self, was: DriveState) -> None:
        """Power stage on/off and set-point bookkeeping for a state change."""
        now = self._state_machine.state
        if now is was:
            return
        if now not in ENERGISED_STATES:
            self._servo.brake()
            self._demand.sync(self._servo.position_counts)
            self._following_error_s = 0.0
        elif was not in ENERGISED_STATES:
            self._demand.sync(self._servo.position_counts)
            self._in_position_window_s = self.node.value(0x6068) / 1000.0  # at rest on the demand: settled
        self._profile_position.reset(self._demand.position_counts)
        self._homing.interrupt()
        if was is DriveState.FAULT:
            self._on_fault_reset()

    def _on_fault_reset(self) -> None:
        """Transition 15: errors that are gone are cleared and EMCY 0x0000 tells so."""
        still_present = frozenset({emergency.CAN_ERROR_PASSIVE}) if self._can_errors.error_passive else frozenset()
        register = self._errors.clear_all_except(still_present)
        self.node.store(0x603F, 0, 0)
        self._emcy(emergency.NO_ERROR, register)

    def _raise_fault(self, error_code: int) -> None:
        """Fault: EMCY with the error register, then the fault reaction (transitions 13, 14)."""
        if error_code in self._errors.codes:
            return
        register = self._errors.raise_error(error_code)
        self.node.store(0x603F, 0, error_code)
        self._emcy(error_code, register)
        was = self._state_machine.state
        self._state_machine.on_fault()
        self._state_machine.on_fault_reaction_done()
        self._after_transitions(was)
        self._publish()

    def _set_position_offset(self, offset_counts: float) -> None:
        """Homing found the reference: the reported position is shifted, the motor does not move."""
        self._position_offset_counts = offset_counts

    def _to_motor_counts(self, drive_counts: float) -> float:
        return drive_counts - self._position_offset_counts

    def _limit(self, target_counts: float) -> tuple[float, bool]:
        """Clamp a motor-frame target into the software position limits 0x607D (min < max: active)."""
        low = self._to_motor_counts(self.node.value(0x607D, 1))
        high = self._to_motor_counts(self.node.value(0x607D, 2))
        if low >= high:
            return target_counts, False
        clamped = min(max(target_counts, low), high)
        return clamped, clamped != target_counts

    def _take_set_point(self, controlword: int) -> None:
        target = self.node.value(0x607A)
        if controlword & RELATIVE_BIT:
            wanted = self._profile_position.last_target_counts + target
        else:
            wanted = self._to_motor_counts(target)
        limited, self._internal_limit = self._limit(wanted)
        self._profile_position.accept(limited, controlword)

    def _profile(self) -> MotionProfile:
        return MotionProfile(velocity_counts_s=min(self.node.value(0x6081), self._servo.max_velocity_counts_s),
                             acceleration_counts_s2=self.node.value(0x6083),
                             deceleration_counts_s2=self.node.value(0x6084))

    def _homing_parameters(self) -> HomingParameters:
        return HomingParameters(method=self.node.value(0x6098), home_offset_counts=self.node.value(0x607C),
                                switch_search_speed_counts_s=self.node.value(0x6099, 1),
                                zero_search_speed_counts_s=self.node.value(0x6099, 2),
                                acceleration_counts_s2=self.node.value(0x609A))

    def _new_homing(self) -> Homing:
        switch_mm = self.spec.negative_limit_switch_mm
        return Homing(None if switch_mm is None else self.spec.to_counts(switch_mm))

    def _cycle_period_s(self) -> float:
        period_us = self.node.value(0x1006)
        return period_us / 1e6 if period_us > 0 else self.spec.cycle_period_s

    def _quick_stop_deceleration(self) -> float:
        option = self.node.value(0x605A)
        return self.node.value(0x6084) if option in (1, 5) else self.node.value(0x6085)

    # --- one communication cycle -------------------------------------------------------------
    def _advance(self, dt_s: float) -> None:
        state = self._state_machine.state
        if state is DriveState.OPERATION_ENABLED:
            self._run_mode(dt_s)
        elif state is DriveState.QUICK_STOP_ACTIVE:
            self._demand.run_at(0.0, self._quick_stop_deceleration(), dt_s)
        if state not in ENERGISED_STATES:
            return
        self._servo.step(self._demand.position_counts, self._demand.velocity_counts_s, dt_s)
        self._check_position_window(dt_s)
        self._check_following_error(dt_s)
        if (self._state_machine.state is DriveState.QUICK_STOP_ACTIVE and self._demand.is_stopped
                and self.node.value(0x605A) in (1, 2, 3, 4)):
            was = self._state_machine.state
            self._state_machine.on_quick_stop_done()
            self._after_transitions(was)

    def _run_mode(self, dt_s: float) -> None:
        mode = self._mode()
        if mode == MODE_PROFILE_POSITION:
            self._profile_position.step(self._demand, self._profile(), dt_s)
        elif mode == MODE_CYCLIC_SYNC_POSITION:
            target, self._internal_limit = self._limit(self._to_motor_counts(self.node.value(0x607A)))
            latch_set_point(self._demand, target, dt_s)
        elif mode == MODE_HOMING:
            halted = bool(self.node.value(0x6040) & HOMING_HALT_BIT)
            offset = self._homing.step(self._demand, self._servo.position_counts, halted,
                                       self._homing_parameters(), dt_s)
            if offset is not None:
                self._set_position_offset(offset)
        else:
            self._demand.run_at(0.0, self._quick_stop_deceleration(), dt_s)

    def _following_error_counts(self) -> float:
        return self._demand.position_counts - self._servo.position_counts

    def _check_position_window(self, dt_s: float) -> None:
        """Time the actual position has stayed within the position window 0x6067 of the demand."""
        if abs(self._following_error_counts()) <= self.node.value(0x6067):
            self._in_position_window_s += dt_s
        else:
            self._in_position_window_s = 0.0

    def _settled(self) -> bool:
        """In the position window for at least the position window time 0x6068."""
        return self._in_position_window_s >= self.node.value(0x6068) / 1000.0 - 1e-9

    def _check_following_error(self, dt_s: float) -> None:
        """CiA 402: |demand - actual| > 0x6065 for longer than 0x6066 ms is a fault (EMCY 0x8611)."""
        window = self.node.value(0x6065)
        if window == FOLLOWING_ERROR_CHECK_OFF or abs(self._following_error_counts()) <= window:
            self._following_error_s = 0.0
            return
        self._following_error_s += dt_s
        if self._following_error_s > self.node.value(0x6066) / 1000.0:
            self._raise_fault(emergency.FOLLOWING_ERROR)

    # --- process values -----------------------------------------------------------------
    def _statusword(self) -> int:
        state = self._state_machine.state
        statusword = state.statusword_bits | REMOTE_BIT
        if emergency.CAN_ERROR_PASSIVE in self._errors.codes:
            statusword |= WARNING_BIT
        if self._internal_limit:
            statusword |= INTERNAL_LIMIT_BIT
        if state is not DriveState.OPERATION_ENABLED:
            return statusword
        mode = self._mode()
        if mode == MODE_PROFILE_POSITION:
            statusword |= self._profile_position.statusword_bits(self._demand, self._settled())
        elif mode == MODE_CYCLIC_SYNC_POSITION:
            statusword |= FOLLOWS_COMMAND_BIT
        elif mode == MODE_HOMING:
            statusword |= self._homing.statusword_bits(self._demand)
        if mode in (MODE_PROFILE_POSITION, MODE_CYCLIC_SYNC_POSITION) and self._following_error_s > 0.0:
            statusword |= FOLLOWING_ERROR_BIT
        return statusword

    def _torque_actual_per_mille(self) -> int:
        rated_mnm = self.node.value(0x6076)
        if rated_mnm == 0:
            return 0
        per_mille = round(1000.0 * self.spec.motor_torque_mnm(self._load_tension_n) / rated_mnm)
        return max(-32768, min(32767, per_mille))

    def _publish(self) -> None:
        """Refresh the read-only process objects, then send event-driven TPDOs that changed."""
        if not self._powered:
            return
        offset = self._position_offset_counts
        self.node.store(0x6041, 0, self._statusword())
        self.node.store(0x6064, 0, round(self._servo.position_counts + offset))
        self.node.store(0x6062, 0, round(self._demand.position_counts + offset))
        self.node.store(0x606C, 0, round(self._servo.velocity_counts_s))
        self.node.store(0x60F4, 0, round(self._following_error_counts()))
        self.node.store(0x6077, 0, self._torque_actual_per_mille())
        self.node.store(0x1001, 0, self._errors.register)
        if self.node.nmt.state_code == OPERATIONAL and not self.silent:
            self._process_data.transmit_changed()
