"""Open the testbed a configuration names: hardware, or the virtual testbed.

This is the one place in crest that may import sim_backend. Everything above it talks to a
`can.BusABC` and a serial port name, and never asks which it got.
"""
from __future__ import annotations

import itertools
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import can

from crest.config import TestbedConfig
from crest.config.testbed_config import AxisConfig

_channel_numbers = itertools.count(1)
INSERTION_START_ABOVE_HOME_MM = 2.0   # the simulated pulley block powers up this far from its switch


class BackendError(ValueError):
    """The requested backend cannot be opened as configured (with the remedy in the message)."""


@dataclass
class Backend:
    """An opened testbed: the host's CAN bus, the tracker's serial port, and the simulator if virtual."""

    bus: can.BusABC
    tracker_port: str
    virtual: object | None = None   # sim_backend.VirtualTestbed when simulated

    @property
    def is_virtual(self) -> bool:
        return self.virtual is not None

    def monitor_bus(self) -> can.BusABC | None:
        """A second handle that sees every frame on the bus, the host's included (virtual bus only)."""
        if self.virtual is None:
            return None
        return can.Bus(interface="virtual", channel=self.virtual.channel)

    def tick(self, now_s: float) -> None:
        """Advance the simulator's time-based duties (deterministic use); no-op on hardware."""
        if self.virtual is not None:
            self.virtual.tick(now_s)

    def close(self) -> None:
        self.bus.shutdown()
        if self.virtual is not None:
            self.virtual.stop()


def fault_kinds() -> dict[str, tuple[str, ...]]:
    """The virtual testbed's fault kinds, for `--fault` help: {'drive': kinds, 'tracker': kinds}."""
    from sim_backend.faults import DRIVE_FAULT_KINDS, TRACKER_FAULT_KINDS

    return {"drive": tuple(sorted(kind.value for kind in DRIVE_FAULT_KINDS)),
            "tracker": tuple(sorted(kind.value for kind in TRACKER_FAULT_KINDS))}


def open_backend(config: TestbedConfig, *, plant: str | None = None, plant_config: Path | None = None,
                 faults: Sequence[str] = (), effects: dict | None = None, realtime: bool = True,
                 plant_in_thread: bool = False, tracker_noise_mm: float | None = None,
                 tracker_dropout: float | None = None) -> Backend:
    """Open the bus and tracker of `config`.

    plant ('package.module:ClassName'), plant_config (the default plant's description, default
    configs/virtual_plant.toml), faults ('AXIS:KIND@SECONDS'), effects ({effect id: {param: value}},
    added to the plant description's) and the tracker's noise and dropout apply to the virtual
    testbed only. realtime=False leaves time to the caller's `Backend.tick` (tests).
    """
    if config.bus.interface != "virtual":
        if (plant or plant_config or faults or effects or tracker_noise_mm is not None
                or tracker_dropout is not None):
            raise BackendError("--plant, --plant-config, --fault and --effect need the virtual testbed; "
                               f"{config.path} selects the real bus '{config.bus.interface}'")
        if config.tracker.port == "sim":
            raise BackendError(f"{config.path}: [tracker].port = 'sim' needs the virtual testbed; "
                               "set it to the tracker's serial device")
        try:
            bus = can.Bus(interface=config.bus.interface, channel=config.bus.channel, bitrate=config.bus.bitrate)
        except (can.CanError, OSError, ValueError, ImportError) as exc:
            raise BackendError(f"cannot open CAN interface '{config.bus.interface}' channel "
                               f"'{config.bus.channel}': {exc}. Check the adapter and [bus] in {config.path}") from exc
        return Backend(bus=bus, tracker_port=config.tracker.port)
    return _open_virtual(config, plant, plant_config, faults, effects or {}, realtime, plant_in_thread,
                         tracker_noise_mm, tracker_dropout)


def _open_virtual(config: TestbedConfig, plant_spec: str | None, plant_toml: Path | None, fault_texts: Sequence[str],
                  effects: dict, realtime: bool, plant_in_thread: bool, tracker_noise_mm: float | None,
                  tracker_dropout: float | None) -> Backend:
    from sim_backend.faults import parse_fault
    from sim_backend.plant import DahlPlant, PlantConfig, load_plant
    from sim_backend.plant.dahl_plant import DEFAULT_PLANT_TOML
    from sim_backend.virtual_testbed import TrackerSettings, VirtualTestbed

    faults = [parse_fault(text) for text in fault_texts]
    plant_config = PlantConfig.from_toml(plant_toml or DEFAULT_PLANT_TOML).with_effects(effects)
    plant = load_plant(plant_spec) if plant_spec else DahlPlant(plant_config)
    specs = [_drive_spec(config, axis) for axis in config.axes]
    # The virtual bus is in-process: a channel of our own per testbed keeps testbeds apart.
    channel = f"{config.bus.channel}-{os.getpid()}-{next(_channel_numbers)}"
    testbed = VirtualTestbed(specs, channel, plant, bitrate_bit_s=config.bus.bitrate,
                             sync_period_s=config.sync.period_s, faults=faults,
                             tracker=TrackerSettings(
                                 plant_config.tracker_noise_mm if tracker_noise_mm is None else tracker_noise_mm,
                                 plant_config.tracker_dropout if tracker_dropout is None else tracker_dropout,
                                 plant_config.tracker_seed, int(config.tracker.tool_port, 16)),
                             plant_in_thread=plant_in_thread)
    testbed.start(realtime=realtime)
    bus = can.Bus(interface="virtual", channel=channel, receive_own_messages=False)
    return Backend(bus=bus, tracker_port=testbed.tracker_port, virtual=testbed)


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
