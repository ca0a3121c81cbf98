"""Motion limits enforced on the host, before anything reaches a drive.

Each axis has soft limits [min, max] mm, a maximum velocity v_max (mm/s) and a maximum
acceleration a_max (mm/s^2). At the SYNC period T a set-point stream x[k] respects them when

    min <= x[k] <= max,   |x[k] - x[k-1]| <= v_max T,   |x[k] - 2 x[k-1] + x[k-2]| <= a_max T^2.

The axes stand before a trajectory and after it, so a trajectory must also start and end at
rest within the acceleration limit. Whole trajectories and point-move targets are refused (MotionRefused names the sample, the axis,
the value and the limit). Set-points streamed one cycle at a time (a closed-loop controller) are
clamped instead, and the cycle reports what was clamped.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from crest.config import AxisConfig, TestbedConfig
from crest.driver.axis_targets import AXIS_ORDER, AxisTargets
from crest.driver.errors import MotionRefused

#: Slack on the velocity and acceleration checks of a planned trajectory: set-points are
#: usually computed in floating point right at the limit.
PLAN_TOLERANCE = 1e-6
#: A caught-up set-point this close to the requested one is the requested one (float rounding).
LANDING_TOLERANCE_MM = 1e-9


def check_positions(config: TestbedConfig, targets: AxisTargets, what: str = "target") -> None:
    """Refuse set-points outside the soft limits."""
    for name, position_mm in targets.by_axis().items():
        axis = config.axis(name)
        if not axis.soft_min_mm <= position_mm <= axis.soft_max_mm:
            raise MotionRefused(name, f"{what} {position_mm:.3f} mm is outside soft_limits_mm "
                                      f"[{axis.soft_min_mm:g}, {axis.soft_max_mm:g}]; nothing was moved")


def check_trajectory(config: TestbedConfig, samples: Sequence[AxisTargets]) -> None:
    """Refuse a trajectory (one sample per SYNC period) that breaks any limit of the module docstring.

    The axes stand before the first sample and after the last, so the trajectory is checked as
    if its first and last samples were repeated: it must start and end at rest within the
    acceleration limit.
    """
    if not samples:
        raise MotionRefused(None, "the trajectory has no samples; nothing was moved")
    period_s = config.sync.period_s
    for number, sample in enumerate(samples):
        check_positions(config, sample, what=f"sample {number}")
    for position, name in enumerate(AXIS_ORDER):
        axis = config.axis(name)
        x = [samples[0].values()[position]] + [sample.values()[position] for sample in samples] \
            + [samples[-1].values()[position]]
        for k in range(1, len(x)):
            where = f"sample {k - 1}" if k - 1 < len(samples) else "after the last sample (the axis stops)"
            velocity_mm_s = (x[k] - x[k - 1]) / period_s
            if abs(velocity_mm_s) > axis.max_velocity_mm_s * (1 + PLAN_TOLERANCE):
                raise MotionRefused(name, f"{where}: velocity {velocity_mm_s:.2f} mm/s exceeds max_velocity_mm_s "
                                          f"{axis.max_velocity_mm_s:g}; slow the trajectory down; nothing was moved")
            if k >= 2:
                acceleration = (x[k] - 2 * x[k - 1] + x[k - 2]) / period_s ** 2
                if abs(acceleration) > axis.max_acceleration_mm_s2 * (1 + PLAN_TOLERANCE):
                    raise MotionRefused(name, f"{where}: acceleration {acceleration:.1f} mm/s^2 exceeds "
                                              f"max_acceleration_mm_s2 {axis.max_acceleration_mm_s2:g}; start and end "
                                              "at rest and smooth the trajectory; nothing was moved")


def braking_velocity_mm_s(distance_mm: float, acceleration_mm_s2: float, period_s: float) -> float:
    """The fastest set-point velocity from which the stream can still stop within ``distance_mm``.

    Each cycle moves v T and the velocity then drops by a T, so stopping from v covers about
    v^2 / (2 a) + v T / 2; setting that equal to the distance e gives

        v = -a T / 2 + sqrt((a T / 2)^2 + 2 a e).
    """
    half_step = acceleration_mm_s2 * period_s / 2.0
    return -half_step + math.sqrt(half_step * half_step + 2.0 * acceleration_mm_s2 * distance_mm)


class SetPointLimiter:
    """Clamps a streamed set-point of one axis into its limits, cycle by cycle.

    A set-point that respects the limits passes unchanged. Otherwise the limiter catches up:
    the commanded velocity v = (x - p) / T is clamped to +-v_max, to the braking bound
    (``braking_velocity_mm_s``, so the axis can stop on the set-point), and to v_prev +- a_max T;
    the position to the soft limits. It keeps catching up (braking included) until it stands
    on the set-point slowly enough to stop within one cycle.
    """

    def __init__(self, axis: AxisConfig, period_s: float, position_mm: float) -> None:
        self.axis = axis
        self.period_s = period_s
        self.reset(position_mm)

    def reset(self, position_mm: float) -> None:
        """Start from rest at ``position_mm``."""
        self.position_mm = position_mm
        self.velocity_mm_s = 0.0
        self._catching_up = False

    def limit(self, requested_mm: float) -> tuple[float, str | None]:
        """(set-point to send, None or a message saying what was clamped and why)."""
        axis, period_s = self.axis, self.period_s
        low_mm, high_mm = axis.soft_min_mm, axis.soft_max_mm
        wanted_mm = min(max(requested_mm, low_mm), high_mm)
        step_mm = wanted_mm - self.position_mm
        velocity = step_mm / period_s
        max_change = axis.max_acceleration_mm_s2 * period_s
        feasible = (abs(velocity) <= axis.max_velocity_mm_s * (1 + PLAN_TOLERANCE)
                    and abs(velocity - self.velocity_mm_s) <= max_change * (1 + PLAN_TOLERANCE))
        if feasible and not self._catching_up:
            set_point_mm = wanted_mm
        else:
            reachable = min(axis.max_velocity_mm_s,
                            braking_velocity_mm_s(abs(step_mm), axis.max_acceleration_mm_s2, period_s))
            goal = max(-reachable, min(reachable, velocity))
            velocity = max(self.velocity_mm_s - max_change, min(self.velocity_mm_s + max_change, goal))
            set_point_mm = min(max(self.position_mm + velocity * period_s, low_mm), high_mm)
            if abs(set_point_mm - wanted_mm) < LANDING_TOLERANCE_MM:
                set_point_mm = wanted_mm
            velocity = (set_point_mm - self.position_mm) / period_s
            self._catching_up = not (set_point_mm == wanted_mm and abs(velocity) <= max_change)
        message = None
        if set_point_mm != wanted_mm:
            message = (f"{axis.name}: set-point {requested_mm:.3f} mm needs {step_mm / period_s:.1f} mm/s from "
                       f"{self.position_mm:.3f} mm; limited to {set_point_mm:.3f} mm by max_velocity_mm_s "
                       f"{axis.max_velocity_mm_s:g} / max_acceleration_mm_s2 {axis.max_acceleration_mm_s2:g}")
        elif wanted_mm != requested_mm:
            message = f"{axis.name}: set-point {requested_mm:.3f} mm clamped to soft limit {wanted_mm:g} mm"
        self.velocity_mm_s = velocity
        self.position_mm = set_point_mm
        return set_point_mm, message
