"""The drive's position demand: the set-point generator that feeds the servo loop.

Every operation mode produces the demand position x_d (counts) and demand
velocity v_d (counts/s) here, one communication cycle dt at a time:

- ``follow`` (cyclic synchronous position): x_d is the latched set-point and
  v_d = (x_d[k] - x_d[k-1]) / dt, the velocity the set-point stream implies.
- ``move_toward`` (profile position): a trapezoidal profile. With e = target - x_d
  and v the demand velocity toward the target, the velocity goal v' for the end
  of this cycle is the fastest from which deceleration d still stops on the
  target after this cycle's travel (v + v') / 2 * dt:

      v'^2 / (2 d) = e - (v + v') / 2 * dt
      =>  v' = (-d dt + sqrt((d dt)^2 + 8 d e - 4 d dt v)) / 2,

  capped at v_max. v_d approaches v' by at most a*dt when speeding up and d*dt
  when slowing down; x_d advances by the trapezoid rule (v_d[k-1] + v_d[k]) / 2 * dt.
- ``run_at`` (homing, quick stop, halt): v_d approaches a velocity at a given rate.
"""

from __future__ import annotations

import math


class SetpointGenerator:
    """Demand position (counts) and velocity (counts/s) of one axis."""

    def __init__(self, position_counts: float = 0.0) -> None:
        self.position_counts = position_counts
        self.velocity_counts_s = 0.0

    def sync(self, position_counts: float) -> None:
        """Start again from rest at a position (the actual position when the drive is enabled)."""
        self.position_counts = position_counts
        self.velocity_counts_s = 0.0

    @property
    def is_stopped(self) -> bool:
        return self.velocity_counts_s == 0.0

    def follow(self, position_counts: float, dt_s: float) -> None:
        """Take a cyclic set-point; the demand velocity is its finite difference."""
        self.velocity_counts_s = (position_counts - self.position_counts) / dt_s
        self.position_counts = position_counts

    def run_at(self, velocity_counts_s: float, rate_counts_s2: float, dt_s: float) -> None:
        """Approach a velocity with at most ``rate_counts_s2`` and integrate the position."""
        self._advance(_approach(self.velocity_counts_s, velocity_counts_s, rate_counts_s2 * dt_s), dt_s)

    def move_toward(self, target_counts: float, max_velocity_counts_s: float,
                    acceleration_counts_s2: float, deceleration_counts_s2: float,
                    dt_s: float) -> bool:
        """One cycle of the trapezoidal profile toward a target; True once at rest on it."""
        error = target_counts - self.position_counts
        v = self.velocity_counts_s
        if abs(error) <= deceleration_counts_s2 * dt_s * dt_s and abs(v) <= deceleration_counts_s2 * dt_s:
            self.sync(target_counts)
            return True
        d_dt = deceleration_counts_s2 * dt_s
        toward = v if error > 0 else -v  # speed toward the target (negative: moving away)
        discriminant = d_dt * d_dt + 8.0 * deceleration_counts_s2 * abs(error) - 4.0 * d_dt * toward
        reachable = 0.5 * (-d_dt + math.sqrt(max(discriminant, 0.0)))
        goal = math.copysign(min(max_velocity_counts_s, max(reachable, 0.0)), error)
        speeding_up = abs(goal) > abs(v) and goal * v >= 0.0
        rate = acceleration_counts_s2 if speeding_up else deceleration_counts_s2
        self._advance(_approach(v, goal, rate * dt_s), dt_s)
        if (target_counts - self.position_counts) * error <= 0.0:
            # Crossed the target within this cycle: the profile ends on it.
            self.sync(target_counts)
            return True
        return False

    def _advance(self, new_velocity_counts_s: float, dt_s: float) -> None:
        self.position_counts += 0.5 * (self.velocity_counts_s + new_velocity_counts_s) * dt_s
        self.velocity_counts_s = new_velocity_counts_s


def _approach(value: float, goal: float, max_step: float) -> float:
    """``value`` moved toward ``goal`` by at most ``max_step``."""
    if abs(goal - value) <= max_step:
        return goal
    return value + math.copysign(max_step, goal - value)
