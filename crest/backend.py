"""Open the testbed a configuration names: hardware, or the virtual testbed.

This is the one place in crest that may import sim_backend. Everything above it talks to a
`can.BusABC` and a serial port name, and never asks which it got.

The virtual testbed ([bus] interface = "virtual") is found in one of two places. When a served
one runs (`crest testbed serve`, its own process; see crest.testbed_service), the commands join it
through python-can's "remote" interface on the channel its state file names, as they would join a
hardware bus. Otherwise a command starts a served testbed process of its own, which ends with it
(crest.testbed_service.auto_start), and joins that. A command in simulated time (`--fast`, most
tests) gets one in simulated time: its stepped clock sends a CANopen TIME stamp on the bus each
time it moves, and the testbed process moves its drives to that time (sim_backend.time_stamps);
a served testbed in real time is no use to it. A command boots the virtual testbed inside its own
process instead, on python-can's in-process bus, with CREST_VIRTUAL_TESTBED=in-process, when its
caller asks (`in_process`: tests that reach into the simulator, the blind benchmark's recordings),
when a served testbed in the other kind of time runs (`--fast` beside a real-time one), or where
what it sets up cannot be handed to another process (a configuration changed in memory, the
tracker's noise and dropout overridden).
"""
from __future__ import annotations

import itertools
import os
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import can

from crest.config import TestbedConfig, load_testbed_config
from crest.config.testbed_config import AxisConfig
from crest.driver.hooked_bus import HookedBus
from crest.testbed_service import ServedTestbed, config_digest, running_testbed
from crest.testbed_service.auto_start import MODE_VARIABLE, OwnedTestbed, start_owned_testbed, wants_own_process
from crest.testbed_service.clock_claim import claim_clock
from crest.testbed_service.served_bus import ServedBus
from sim_backend.time_stamps import StampAnswers, fault_clock_frame, time_stamp_frame

_channel_numbers = itertools.count(1)
INSERTION_START_ABOVE_HOME_MM = 2.0   # the simulated pulley block powers up this far from its switch
STAMP_ANSWER_TIMEOUT_S = 10.0   # wall time a testbed in simulated time may take to answer a TIME stamp


class BackendError(ValueError):
    """The requested backend cannot be opened as configured (with the remedy in the message)."""


@dataclass
class Backend:
    """An opened testbed: the host's CAN bus, the tracker's serial port, and the simulator if virtual."""

    bus: HookedBus
    tracker_port: str
    virtual: object | None = None   # sim_backend.VirtualTestbed when simulated in this process
    served: ServedTestbed | None = None   # the served virtual testbed this process joined
    owned: OwnedTestbed | None = None     # ... when this process started it for itself
    stamp_answers: StampAnswers | None = None   # ... when it runs in simulated time
    clock_lock_fd: int | None = None            # ... whose clock this process alone drives
    plant: str | None = None        # the virtual testbed's plant, one line (plant_summary); None on hardware

    @property
    def is_virtual(self) -> bool:
        return self.virtual is not None or self.served is not None

    @contextmanager
    def tapped(self, listener: can.Listener) -> Iterator[None]:
        """`listener` sees every frame the host sends and receives until the block ends, on the host's
        own handle (crest.driver.hooked_bus: a second handle would miss the host's frames on hardware,
        and have a served testbed send every frame twice)."""
        self.bus.tap(listener.on_message_received)
        try:
            yield
        finally:
            self.bus.untap(listener.on_message_received)

    def tracker_port_alive(self) -> bool:
        """May the tracker's port be opened again after its link was lost? A hardware port, yes: an
        adapter plugged in again comes back under its name. A served testbed's pseudo-terminal only while
        that testbed's bus is connected: once its process has ended, the terminal's number may belong
        to the next testbed that starts."""
        return self.served is None or self.bus.inner.lost is None

    def start_fault_clock(self) -> None:
        """The virtual testbed's --fault times count from now (the start of the run's motion):
        the testbed in this process starts its clock; one this process started hears it on the
        bus in simulated time, in order with the TIME stamps (sim_backend.time_stamps), and on its
        pipe in real time. No-op on hardware and on a served testbed this process did not start."""
        if self.virtual is not None:
            self.virtual.start_fault_clock()
        elif self.owned is not None and self.stamp_answers is not None:
            self.bus.send(fault_clock_frame())
        elif self.owned is not None:
            self.owned.start_fault_clock()

    def tick(self, now_s: float) -> None:
        """Advance the simulator's time-based duties (simulated time): the testbed in this process,
        or a served one in simulated time through a TIME stamp on the bus, once the previous stamp
        is answered (sim_backend.time_stamps); no-op on hardware."""
        if self.virtual is not None:
            self.virtual.tick(now_s)
        elif self.stamp_answers is not None:
            self.stamp_answers.wait_for_last(STAMP_ANSWER_TIMEOUT_S, gone=lambda: self.bus.inner.lost is not None)
            self.bus.send(time_stamp_frame(now_s))
            self.stamp_answers.sent(now_s)

    def close(self) -> None:
        self.bus.shutdown()
        if self.virtual is not None:
            self.virtual.stop()
        if self.owned is not None:
            self.owned.stop()
        if self.clock_lock_fd is not None:
            os.close(self.clock_lock_fd)
            self.clock_lock_fd = None


def fault_kinds() -> dict[str, tuple[str, ...]]:
    """The virtual testbed's fault kinds, for `--fault` help: {'drive': kinds, 'tracker': kinds}."""
    from sim_backend.faults import DRIVE_FAULT_KINDS, TRACKER_FAULT_KINDS

    return {"drive": tuple(sorted(kind.value for kind in DRIVE_FAULT_KINDS)),
            "tracker": tuple(sorted(kind.value for kind in TRACKER_FAULT_KINDS))}


def open_backend(config: TestbedConfig, *, plant: str | None = None, plant_config: Path | None = None,
                 faults: Sequence[str] = (), effects: dict | None = None, realtime: bool = True,
                 in_process: bool = False, tracker_noise_mm: float | None = None,
                 tracker_dropout: float | None = None) -> Backend:
    """Open the bus and tracker of `config`.

    plant ('package.module:ClassName'), plant_config (the plant description, default
    configs/virtual_plant.toml; its `family` picks the Dahl or the rod plant), faults ('AXIS:KIND@SECONDS'), effects ({effect id: {param: value}},
    added to the plant description's) and the tracker's noise and dropout apply to the virtual
    testbed only. realtime=False leaves time to the caller's `Backend.tick` (simulated time: `--fast`, tests).
    in_process: the virtual testbed boots inside this process (see crest.session.SessionOptions).
    """
    if config.bus.interface != "virtual":
        if (plant or plant_config or faults or effects or tracker_noise_mm is not None
                or tracker_dropout is not None):
            raise BackendError("--plant, --plant-config, --fault and --effect need the virtual testbed; "
                               f"{config.path} selects the real bus '{config.bus.interface}'")
        if config.tracker.port == "sim":
            raise BackendError(f"{config.path}: [tracker].port = 'sim' needs the virtual testbed; "
                               "set it to the tracker's serial device")
        return Backend(bus=HookedBus(_open_hardware_bus(config)), tracker_port=config.tracker.port)
    effects = effects or {}
    if in_process:
        return _open_virtual(config, plant, plant_config, faults, effects, realtime, tracker_noise_mm, tracker_dropout)
    served = running_testbed()
    if served is not None and realtime and served.simulated_time:
        raise BackendError(f"the served virtual testbed ({served.describe()}) moves only with the simulated time of a "
                           "command run with --fast; add --fast, or stop it and serve one in real time")
    # a command in simulated time drives the clock of the testbed process it joins or starts: one at a
    # time (crest.testbed_service.clock_claim); a second one keeps its testbed in its own process
    clock_lock_fd = None
    if not realtime and wants_own_process() and (served is None or served.simulated_time):
        clock_lock_fd = claim_clock()
        if clock_lock_fd is None:
            return _open_virtual(config, plant, plant_config, faults, effects, realtime, tracker_noise_mm,
                                 tracker_dropout)
    try:
        backend = _open_process_backend(config, served, realtime, plant, plant_config, faults, effects,
                                        tracker_noise_mm, tracker_dropout)
    except BaseException:
        if clock_lock_fd is not None:
            os.close(clock_lock_fd)
        raise
    if backend.stamp_answers is not None:
        backend.clock_lock_fd = clock_lock_fd
    elif clock_lock_fd is not None:
        os.close(clock_lock_fd)
    return backend


def _open_process_backend(config: TestbedConfig, served: ServedTestbed | None, realtime: bool, plant: str | None,
                          plant_config: Path | None, faults: Sequence[str], effects: dict,
                          tracker_noise_mm: float | None, tracker_dropout: float | None) -> Backend:
    """The served testbed joined, a testbed process of this command's own, or, where the command's
    set-up cannot be handed over or a served testbed in the other kind of time runs, one in this process."""
    if served is not None and served.simulated_time != realtime:
        if plant or plant_config or faults or effects or tracker_noise_mm is not None or tracker_dropout is not None:
            raise BackendError("--plant, --plant-config, --fault, --effect and the tracker's noise and dropout "
                               f"set up a virtual testbed when it starts, but a served one is running ({served.describe()}); "
                               "stop it, or pass them to `crest testbed serve`, or drop them")
        return _joined(config, served)
    # a testbed process is given the configuration's file, the plant and the faults; a configuration
    # changed in memory (not its file's values) and the tracker overrides stay in this process, and
    # beside a served testbed in real time (one server per user) a command in simulated time keeps its own
    if (served is None and wants_own_process() and tracker_noise_mm is None and tracker_dropout is None
            and config_digest(load_testbed_config(config.path)) == config_digest(config)):
        return _open_owned(config, plant, plant_config, effects, faults, simulated_time=not realtime)
    return _open_virtual(config, plant, plant_config, faults, effects, realtime, tracker_noise_mm, tracker_dropout)


def _open_owned(config: TestbedConfig, plant: str | None, plant_config: Path | None, effects: dict,
                faults: Sequence[str], simulated_time: bool) -> Backend:
    """A served testbed process of this command's own, joined (it ends when this process does).
    The faults are checked here, before the process starts, as the testbed checks them."""
    from sim_backend.faults import check_fault_axes, parse_fault

    check_fault_axes([parse_fault(text) for text in faults], [axis.name for axis in config.axes])
    owned = start_owned_testbed(config.path, plant, plant_config, effects, faults, simulated_time)
    try:
        backend = _joined(config, owned.served)
    except BackendError:
        owned.stop()
        raise
    backend.owned = owned
    return backend


def _joined(config: TestbedConfig, served: ServedTestbed) -> Backend:
    """The backend of a served testbed, joined; in simulated time its bus hands every frame to the
    answers of the TIME stamps (sim_backend.time_stamps)."""
    bus = HookedBus(_join_served(config, served))
    backend = Backend(bus=bus, tracker_port=served.tracker_port, served=served,
                      plant=served.plant or "not said (a testbed served by an older crest)")
    if served.simulated_time:
        backend.stamp_answers = StampAnswers()
        bus.receive_hooks = [backend.stamp_answers.on_frame]
    return backend


def join_bus(config: TestbedConfig) -> can.BusABC:
    """A handle on the CAN bus of `config` for a process beside the master (``crest estop``).

    A hardware bus, or the bus of a served virtual testbed (`crest testbed serve`, or the one a
    running command started). Without one this raises BackendError (opening a virtual testbed here
    would boot drives of our own and reach nobody's). The tracker is not opened.
    """
    if config.bus.interface != "virtual":
        return _open_hardware_bus(config)
    served = running_testbed()
    if served is None:
        raise BackendError(f"no virtual testbed is running ({config.path}: [bus] interface = 'virtual'): no crest "
                           "command has started one, and none is served (`crest testbed serve`). A command run with "
                           f"{MODE_VARIABLE}=in-process (or with --fast beside a testbed served in real time) keeps its "
                           "testbed inside its own process, where no other process can reach it: stop that run with "
                           "Ctrl-C (or SIGTERM)")
    return _join_served(config, served)


def _join_served(config: TestbedConfig, served: ServedTestbed) -> can.BusABC:
    if served.config_digest != config_digest(config):
        where = "" if Path(served.config).resolve() == Path(config.path).resolve() else f", not of {config.path}"
        raise BackendError(f"the served virtual testbed ({served.describe()}) serves the drives of {served.config} "
                           f"as it was when the testbed started{where}; this command runs with other values. "
                           f"Use --config {served.config} unchanged, or stop the testbed and serve this configuration")
    try:
        return ServedBus(served.bus_channel, bitrate=config.bus.bitrate)
    except (can.CanError, OSError) as exc:
        raise BackendError(f"cannot join the served virtual testbed ({served.describe()}): {exc}. "
                           "Is it still starting, or stuck? Stop it and start it again") from exc


def _open_hardware_bus(config: TestbedConfig) -> can.BusABC:
    try:
        return can.Bus(interface=config.bus.interface, channel=config.bus.channel, bitrate=config.bus.bitrate)
    except (can.CanError, OSError, ValueError, ImportError) as exc:
        raise BackendError(f"cannot open CAN interface '{config.bus.interface}' channel "
                           f"'{config.bus.channel}': {exc}. Check the adapter and [bus] in {config.path}") from exc


def _open_virtual(config: TestbedConfig, plant_spec: str | None, plant_toml: Path | None, fault_texts: Sequence[str],
                  effects: dict, realtime: bool, tracker_noise_mm: float | None,
                  tracker_dropout: float | None) -> Backend:
    # The virtual bus is in-process: a channel of our own per testbed keeps testbeds apart.
    channel = f"{config.bus.channel}-{os.getpid()}-{next(_channel_numbers)}"
    testbed = _virtual_testbed(config, channel, plant_spec, plant_toml, fault_texts, effects, True,
                               tracker_noise_mm, tracker_dropout)
    testbed.start(realtime=realtime)
    bus = HookedBus(can.Bus(interface="virtual", channel=channel, receive_own_messages=False))
    return Backend(bus=bus, tracker_port=testbed.tracker_port, virtual=testbed,
                   plant=plant_summary(plant_spec, plant_toml, effects))


@dataclass
class VirtualTestbedServer:
    """A virtual testbed running in this process with its bus served to other processes."""

    bus_interface: str      # the python-can interface and channel other processes open
    bus_channel: str
    tracker_port: str
    testbed: object         # sim_backend.VirtualTestbed
    server: object          # sim_backend.bus_server.BusServer

    def stop(self) -> None:
        self.server.stop()
        self.testbed.stop()


def serve_virtual_testbed(config: TestbedConfig, *, plant: str | None = None, plant_config: Path | None = None,
                          effects: dict | None = None, faults: Sequence[str] = (), faults_wait_for_run: bool = False,
                          port: int = 0, simulated_time: bool = False) -> VirtualTestbedServer:
    """Start the virtual testbed of `config` and serve its CAN bus on 127.0.0.1:port (0: any free
    port) over python-can-remote. Its clock: real time, or with simulated_time the TIME stamps on
    the bus (sim_backend.time_stamps). plant, plant_config, effects and faults as for
    `open_backend`; the faults' clock starts now, or with faults_wait_for_run at the testbed's
    `start_fault_clock`."""
    from sim_backend.bus_server import BusServer

    if config.bus.interface != "virtual":
        raise BackendError(f"{config.path} selects the real bus '{config.bus.interface}'; only the virtual testbed "
                           "([bus] interface = 'virtual') can be served")
    channel = f"{config.bus.channel}-served-{os.getpid()}"
    testbed = _virtual_testbed(config, channel, plant, plant_config, faults, effects or {}, faults_wait_for_run,
                               None, None)
    testbed.start(realtime=not simulated_time, time_stamps=simulated_time)
    try:
        server = BusServer(channel, port).start()
    except OSError as exc:
        testbed.stop()
        raise BackendError(f"cannot serve the virtual testbed's bus on 127.0.0.1:{port}: {exc}; "
                           "choose another --port (0 picks a free one)") from exc
    return VirtualTestbedServer("remote", server.url, testbed.tracker_port, testbed, server)


def _virtual_testbed(config: TestbedConfig, channel: str, plant_spec: str | None, plant_toml: Path | None,
                     fault_texts: Sequence[str], effects: dict, faults_wait_for_run: bool,
                     tracker_noise_mm: float | None, tracker_dropout: float | None):
    from sim_backend.faults import parse_fault
    from sim_backend.plant import load_plant
    from sim_backend.plant.plant_description import load_plant_description
    from sim_backend.virtual_testbed import TrackerSettings, VirtualTestbed

    faults = [parse_fault(text) for text in fault_texts]
    described_plant, tracker = load_plant_description(plant_toml, effects)
    plant = load_plant(plant_spec) if plant_spec else described_plant
    specs = [_drive_spec(config, axis) for axis in config.axes]
    return VirtualTestbed(specs, channel, plant, sync_period_s=config.sync.period_s, faults=faults,
                          faults_wait_for_run=faults_wait_for_run,
                          tracker=TrackerSettings(
                              tracker.noise_mm if tracker_noise_mm is None else tracker_noise_mm,
                              tracker.dropout if tracker_dropout is None else tracker_dropout,
                              tracker.seed, int(config.tracker.tool_port, 16)))


def _drive_spec(config: TestbedConfig, axis: AxisConfig):
    from sim_backend.drive.drive_spec import DriveSpec

    is_insertion = axis.kind == "insertion"
    return DriveSpec(
        name=axis.name, node_id=axis.node_id, eds_path=axis.eds_path,
        encoder_counts_per_rev=axis.encoder_counts_per_rev, gear_ratio=axis.gear_ratio,
        drum_radius_mm=axis.drum_radius_mm, soft_limits_mm=axis.soft_limits_mm,
        homing_method=axis.homing_method, max_velocity_mm_s=axis.max_velocity_mm_s,
        max_acceleration_mm_s2=axis.max_acceleration_mm_s2, rated_torque_mnm=axis.rated_torque_mnm,
        following_error_window_mm=axis.following_error_window_mm, home_position_mm=axis.home_position_mm,
        # the pulley block's negative limit switch sits at the home position, and the block starts
        # just beyond it; the tendon shafts start at zero
        negative_limit_switch_mm=axis.home_position_mm if is_insertion else None,
        start_position_mm=axis.home_position_mm + INSERTION_START_ABOVE_HOME_MM if is_insertion else 0.0,
        master_node_id=config.master.node_id, heartbeat_period_s=config.master.drive_heartbeat_period_s,
        heartbeat_timeout_s=config.master.heartbeat_timeout_s, cycle_period_s=config.sync.period_s)


def plant_effect_ranges(family: str) -> dict:
    """The effects a plant family implements and the ranges to draw their parameters from:
    {effect id: {"in_catalog": bool, "physics": str, "params": {name: {"low", "typical", "high",
    "draw", "allowed"}}}}; draw is "log", "log_signed" or "uniform". family: "dahl" or "rod"."""
    from sim_backend.plant.plant_description import plant_effect_ranges as ranges

    return ranges(family)


def plant_from_description(plant_toml: Path | None, effects: dict | None = None):
    """The plant a plant TOML describes (for benchmarks): has reset() and
    step(dt_s, tendon_mm[4], insertion_mm) -> (tip_mm[3], tendon_tension_n[4])."""
    from sim_backend.plant.plant_description import load_plant_description

    return load_plant_description(plant_toml, effects)[0]


def plant_summary(plant: str | None, plant_config: Path | None, effects: dict | None = None) -> str:
    """What the virtual testbed simulates behind its drives, in one line, and whether a result on it
    says anything beyond the controller's own model: the Dahl family runs `model`'s own kernel with
    other parameters (a result on it is in family); the rod family shares no code with `model`
    (out of family). A plant class given as MODULE:CLASS is named as given."""
    added = f" with {', '.join(sorted(effects))}" if effects else ""
    if plant:
        return f"{plant}{added} (--plant: a plant class of your own)"
    if plant_description_family(plant_config) == "rod":
        return (f"rod family ({plant_config}){added}: a Kirchhoff rod written independently of the controller's "
                "model, so results on it are out of family")
    from sim_backend.plant.dahl_plant import DEFAULT_PLANT_TOML

    return (f"Dahl family ({plant_config or DEFAULT_PLANT_TOML}){added}: the controller's own model with other "
            "parameters, so results on it are in family (configs/rod_plant.toml is the independent rod plant)")


def plant_description_refusal(plant_toml: Path) -> str | None:
    """Why the virtual testbed cannot build the plant this TOML describes (its description's own
    check, e.g. a lumen drift that puts the lumens outside the shaft); None where it can."""
    try:
        plant_from_description(plant_toml)
    except ValueError as error:     # the plant descriptions' errors (sim_backend.plant) are ValueErrors
        return str(error)
    return None


def plant_description_family(plant_toml: Path | None) -> str:
    """The plant family ("dahl" or "rod") a plant TOML describes (None: configs/virtual_plant.toml, "dahl")."""
    from sim_backend.plant.plant_description import plant_family

    return "dahl" if plant_toml is None else plant_family(plant_toml)
