"""The motor and its position loop: the actual position lags the demand.

The drive runs its loop every h, at most 0.5 / K_p (10 ms), whatever the SYNC period: a
communication cycle dt is n = ceil(dt / h_max) loop periods h = dt / n, in which the cycle's end
demand x_d is walked back along v_d (loop k = 1..n ends at x_d - v_d (dt - k h)). Per loop period h,
with demand x_d, v_d at its end and actual x, v (counts, counts/s):

    e     = (x_d - v_d * h) - x           tracking error at the start of the loop period
    v_cmd = v_d + sign(e) * min(K_p * |e|, sqrt(2 * a_max * |e|))
    v_cmd = clamp(v_cmd, -v_max, v_max)
    v    <- v + clamp(v_cmd - v, -a_max * h, a_max * h)
    x    <- x + (v_old + v) / 2 * h

i.e. a proportional position loop with velocity feed-forward. The correction is
capped by sqrt(2 a_max |e|) so that a jump in the demand is approached without
overshoot, and the motor's velocity and acceleration limits make the actual
position fall behind any demand that is faster or accelerates harder than the
motor can. A stalled motor (jammed load) does not move at all, so the
following error e grows with the demand.
"""

from __future__ import annotations

import math

#: Position loop gain K_p (1/s). K_p * h = 0.5 at the 10 ms loop period: no overshoot.
DEFAULT_POSITION_GAIN_1_S = 50.0
#: The longest loop period, as a fraction of 1 / K_p: beyond 1 the discrete loop overshoots, at 2 it oscillates.
LOOP_GAIN_PER_PERIOD = 0.5


class ServoAxis:
    """Actual position and velocity of one motor, in encoder counts."""

    def __init__(self, max_velocity_counts_s: float, max_acceleration_counts_s2: float,
                 position_counts: float = 0.0,
                 position_gain_1_s: float = DEFAULT_POSITION_GAIN_1_S) -> None:
        self.max_velocity_counts_s = max_velocity_counts_s
        self.max_acceleration_counts_s2 = max_acceleration_counts_s2
        self.position_gain_1_s = position_gain_1_s
        self.position_counts = position_counts
        self.velocity_counts_s = 0.0
        self.stalled = False

    def step(self, demand_counts: float, demand_velocity_counts_s: float, dt_s: float) -> None:
        """Advance the energised motor by one communication cycle toward the demand at its end."""
        if self.stalled:
            self.velocity_counts_s = 0.0
            return
        loops = max(1, math.ceil(dt_s * self.position_gain_1_s / LOOP_GAIN_PER_PERIOD - 1e-9))
        loop_s = dt_s / loops
        for k in range(1, loops + 1):
            self._loop(demand_counts - demand_velocity_counts_s * (dt_s - k * loop_s), demand_velocity_counts_s, loop_s)

    def _loop(self, demand_counts: float, demand_velocity_counts_s: float, dt_s: float) -> None:
        """One period of the position loop (the module docstring, with h = dt_s)."""
        error = demand_counts - demand_velocity_counts_s * dt_s - self.position_counts
        correction = min(self.position_gain_1_s * abs(error),
                         math.sqrt(2.0 * self.max_acceleration_counts_s2 * abs(error)))
        command = demand_velocity_counts_s + math.copysign(correction, error)
        command = max(-self.max_velocity_counts_s, min(self.max_velocity_counts_s, command))
        max_change = self.max_acceleration_counts_s2 * dt_s
        new_velocity = self.velocity_counts_s + max(-max_change, min(max_change, command - self.velocity_counts_s))
        self.position_counts += 0.5 * (self.velocity_counts_s + new_velocity) * dt_s
        self.velocity_counts_s = new_velocity

    def brake(self) -> None:
        """Power stage off, holding brake engaged: the motor stands where it is."""
        self.velocity_counts_s = 0.0
