"""The parameters the driver writes into each drive by SDO, computed from the axis configuration.

Lengths become encoder counts with ``AxisConfig.counts_per_mm``:

    0x1006      communication cycle period = SYNC period, us (the drive's CSP interpolation step)
    0x6081      profile velocity          = max_velocity_mm_s * counts_per_mm            (counts/s)
    0x6083/84   profile acceleration / deceleration = max_acceleration_mm_s2 * counts_per_mm (counts/s^2)
    0x6085      quick stop deceleration   = max_acceleration_mm_s2 * counts_per_mm
    0x605A      quick stop option code 2: stop on the quick stop ramp, then SWITCH ON DISABLED
    0x607D:1/2  software position limits  = soft_limits_mm * counts_per_mm           (counts)
    0x6065      following error window    = following_error_window_mm * counts_per_mm (counts)
    0x6098      homing method; 0x607C home offset = home_position_mm * counts_per_mm
    0x6099:1/2  homing speeds: switch search 1/2, zero search 1/10 of max velocity  (counts/s)
    0x609A      homing acceleration       = max acceleration
    0x1017      producer heartbeat time   = drive_heartbeat_period_s                 (ms)
    0x1016:1    consumer heartbeat time: master node id << 16 | heartbeat_timeout_s (ms)

0x6076 (motor rated torque) is not written, it belongs to the motor: it is read and compared
with ``rated_torque_mnm``, because tendon tension is computed from torque actual per mille of it.
"""

from __future__ import annotations

from dataclasses import dataclass

from crest.config import AxisConfig, TestbedConfig
from crest.driver.drive_axis import DriveAxis
from crest.driver.errors import ReadBackMismatch

QUICK_STOP_OPTION = 2
HOMING_SWITCH_SPEED_FRACTION = 0.5
HOMING_ZERO_SPEED_FRACTION = 0.1
MOTOR_RATED_TORQUE = 0x6076
CONSUMER_HEARTBEAT_TIME = 0x1016


@dataclass(frozen=True)
class Parameter:
    index: int
    subindex: int
    value: int
    what: str


def drive_parameters(axis: AxisConfig, config: TestbedConfig) -> tuple[Parameter, ...]:
    """The parameters of the module docstring except the heartbeat consumer, in writing order."""
    per_mm = axis.counts_per_mm
    velocity = round(axis.max_velocity_mm_s * per_mm)
    acceleration = round(axis.max_acceleration_mm_s2 * per_mm)
    return (
        Parameter(0x1006, 0, round(config.sync.period_s * 1e6), "communication cycle period (us)"),
        Parameter(0x6081, 0, velocity, "profile velocity"),
        Parameter(0x6083, 0, acceleration, "profile acceleration"),
        Parameter(0x6084, 0, acceleration, "profile deceleration"),
        Parameter(0x6085, 0, acceleration, "quick stop deceleration"),
        Parameter(0x605A, 0, QUICK_STOP_OPTION, "quick stop option code"),
        Parameter(0x607D, 1, axis.mm_to_counts(axis.soft_min_mm), "software position limit min"),
        Parameter(0x607D, 2, axis.mm_to_counts(axis.soft_max_mm), "software position limit max"),
        Parameter(0x6065, 0, round(axis.following_error_window_mm * per_mm), "following error window"),
        Parameter(0x6098, 0, axis.homing_method, "homing method"),
        Parameter(0x607C, 0, axis.mm_to_counts(axis.home_position_mm), "home offset"),
        Parameter(0x6099, 1, round(HOMING_SWITCH_SPEED_FRACTION * axis.max_velocity_mm_s * per_mm),
                  "homing speed during search for switch"),
        Parameter(0x6099, 2, round(HOMING_ZERO_SPEED_FRACTION * axis.max_velocity_mm_s * per_mm),
                  "homing speed during search for zero"),
        Parameter(0x609A, 0, acceleration, "homing acceleration"),
        Parameter(0x1017, 0, round(config.master.drive_heartbeat_period_s * 1000), "producer heartbeat time (ms)"),
    )


def consumer_heartbeat_entry(config: TestbedConfig) -> int:
    """0x1016:1: watch the master's heartbeat, fault when it is silent for heartbeat_timeout_s."""
    return config.master.node_id << 16 | round(config.master.heartbeat_timeout_s * 1000)


def write_parameters(axis: DriveAxis, config: TestbedConfig) -> None:
    """Write and read back every parameter; check the motor rated torque matches the config."""
    for parameter in drive_parameters(axis.config, config):
        axis.sdo.write_verified(parameter.index, parameter.subindex, parameter.value, f"configure {parameter.what}")
    rated_mnm = axis.sdo.read(MOTOR_RATED_TORQUE, 0, "check motor rated torque")
    if rated_mnm != round(axis.config.rated_torque_mnm):
        raise ReadBackMismatch(axis.name, f"motor rated torque 0x6076 is {rated_mnm} mNm but the configuration says "
                                          f"rated_torque_mnm = {axis.config.rated_torque_mnm:g}; tendon tension would "
                                          "be computed wrong; set rated_torque_mnm to the motor's value")


def write_heartbeat_consumer(axis: DriveAxis, config: TestbedConfig) -> None:
    """Last step of configuration: from the master's first heartbeat on, the drive watches it."""
    axis.sdo.write_verified(CONSUMER_HEARTBEAT_TIME, 1, consumer_heartbeat_entry(config),
                            "configure consumer heartbeat (watch the host)")
