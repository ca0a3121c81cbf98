"""Plain parameters of one simulated drive (no dependency on the crest configuration).

Position scaling: one motor revolution is ``encoder_counts_per_rev`` counts at the
motor, ``gear_ratio`` motor revolutions turn the drum once, and one drum turn
moves the tendon (or pulley belt) by 2 pi r, so

    counts_per_mm = encoder_counts_per_rev * gear_ratio / (2 pi drum_radius_mm).

Load torque at the motor: a tension T (N) on the drum of radius r (mm) needs
T * r / gear_ratio (N mm = mNm) at the motor; 0x6077 reports it in per mille of
the motor rated torque 0x6076.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class DriveSpec:
    """One axis' drive. Lengths in mm of tendon or pulley travel, times in s.

    ``max_velocity_mm_s`` and ``max_acceleration_mm_s2`` are the axis limits: the
    drive's profile defaults (0x6081, 0x6083, 0x6084, 0x6085) use them. The motor
    can do ``motor_velocity_reserve`` and ``motor_acceleration_reserve`` times
    more (a servo is sized with speed and torque reserve), so it can follow a
    profile at the axis limits; a demand beyond what the motor can do is followed
    with a lag.

    ``negative_limit_switch_mm`` places the simulated negative limit switch (None:
    no switch wired, so homing method 17 ends in a homing error). Put it at
    ``home_position_mm`` so that homing on it makes the drive report the plant's
    frame. ``start_position_mm`` is where the axis stands at power-up; before
    homing the drive reports that position.
    """

    name: str
    node_id: int
    eds_path: Path
    encoder_counts_per_rev: int
    gear_ratio: float
    drum_radius_mm: float
    soft_limits_mm: tuple[float, float]
    homing_method: int
    max_velocity_mm_s: float
    max_acceleration_mm_s2: float
    rated_torque_mnm: float
    following_error_window_mm: float
    following_error_timeout_s: float = 0.05
    motor_velocity_reserve: float = 1.25
    motor_acceleration_reserve: float = 2.0
    position_window_mm: float = 0.02
    home_position_mm: float = 0.0
    negative_limit_switch_mm: float | None = None
    start_position_mm: float = 0.0
    master_node_id: int = 127
    heartbeat_period_s: float = 0.05
    heartbeat_timeout_s: float = 0.25
    cycle_period_s: float = 0.01

    def __post_init__(self) -> None:
        where = f"drive {self.name!r} (node {self.node_id})"
        if not 1 <= self.node_id <= 127:
            raise ValueError(f"{where}: node_id must be 1..127")
        if not 1 <= self.master_node_id <= 127 or self.master_node_id == self.node_id:
            raise ValueError(f"{where}: master_node_id must be 1..127 and differ from the drive's node id")
        for field_name in ("encoder_counts_per_rev", "gear_ratio", "drum_radius_mm", "max_velocity_mm_s",
                           "max_acceleration_mm_s2", "rated_torque_mnm",
                           "motor_velocity_reserve", "motor_acceleration_reserve", "following_error_window_mm",
                           "position_window_mm", "heartbeat_period_s", "heartbeat_timeout_s", "cycle_period_s"):
            if not getattr(self, field_name) > 0:
                raise ValueError(f"{where}: {field_name} must be > 0, got {getattr(self, field_name)!r}")
        low, high = self.soft_limits_mm
        if not low < high:
            raise ValueError(f"{where}: soft_limits_mm must be [min, max] with min < max, got {self.soft_limits_mm!r}")
        if not Path(self.eds_path).is_file():
            raise ValueError(f"{where}: EDS file {self.eds_path} does not exist")

    @property
    def counts_per_mm(self) -> float:
        return self.encoder_counts_per_rev * self.gear_ratio / (2.0 * math.pi * self.drum_radius_mm)

    def to_counts(self, mm: float) -> float:
        return mm * self.counts_per_mm

    def motor_torque_mnm(self, tension_n: float) -> float:
        """Torque at the motor shaft that holds a tension on the drum (mNm)."""
        return tension_n * self.drum_radius_mm / self.gear_ratio
