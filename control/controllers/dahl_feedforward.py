"""`dahl`: friction-aware feedforward that inverts the Dahl catheter model online, open loop.

Each cycle: solve for the command the model predicts puts the tip on the target (DahlInverse),
warm-started from the previous solution moved by the constant-curvature increment of the
set-point, x0 = x_prev + (x_cc,k - x_cc,k-1); keep it inside the range and rate box; then drive
the model with the command actually sent. The model's friction state therefore follows the
catheter's own input history, and the hysteresis is compensated along the whole path,
reversals included.

The free length may differ from the set-point's by at most max_insertion_offset_mm: at large
articulation the model's shape is far from an arc and reaching the arc's tip exactly would
take large insertion moves (about -26 mm at 270 deg); beyond the bound the tip error stays.
"""
from __future__ import annotations

import numpy as np

from model import DahlCatheter

from control.command_limiter import CommandLimiter
from control.controllers.controller import Controller, checked_setpoint
from control.dahl_inverse import DahlInverse
from control.inverse_kinematics import tendons_from_pulls
from control.model_reset import reset_straight
from control.motion_limits import MotionLimits
from control.setpoint import SetPoint
from control.tendon_command import TendonCommand
from control.tip_measurement import TipMeasurement
from control.workspace import Workspace


class DahlFeedforward(Controller):
    """model: the controller's DahlCatheter (workspace.params, n_elements), state = what was sent."""

    name = "dahl"

    def __init__(self, workspace: Workspace, limits: MotionLimits = MotionLimits(), period_s: float = 0.01, *,
                 n_elements: int = 20, insertion_weight: float = 1e-3, tolerance_mm: float = 0.03,
                 max_insertion_offset_mm: float = 10.0):
        if not max_insertion_offset_mm >= 0:
            raise ValueError(f"max_insertion_offset_mm must be >= 0, got {max_insertion_offset_mm!r}")
        self.workspace = workspace
        self.max_insertion_offset_mm = float(max_insertion_offset_mm)
        self.model = DahlCatheter(workspace.params, n_elements)
        self.inverse = DahlInverse(self.model, workspace.pretension_mm, insertion_weight=insertion_weight,
                                   tolerance_mm=tolerance_mm)
        self.limiter = CommandLimiter(workspace, limits, period_s)
        self.reset()

    def reset(self, insertion_mm: float | None = None) -> None:
        insertion_mm = self.workspace.home_insertion_mm if insertion_mm is None else insertion_mm
        reset_straight(self.model, insertion_mm)
        self.inverse.reset()
        self.limiter.reset(insertion_mm=insertion_mm)
        self._x: np.ndarray | None = None       # last command sent, (p_x, p_y, L)
        self._x_cc: np.ndarray | None = None    # the constant-curvature command of the last set-point

    def command(self, setpoint: SetPoint, tip: TipMeasurement | None = None,
                drive_tension_n: np.ndarray | None = None) -> TendonCommand:
        return self.command_toward(checked_setpoint(setpoint, self.workspace).tip_mm, setpoint)

    def command_toward(self, target_tip_mm, setpoint: SetPoint) -> TendonCommand:
        """The command for `target_tip_mm` (the set-point's tip, or a corrected one from feedback)."""
        x_cc = np.append(self.workspace.tendon_offset_mm * setpoint.articulation.bend_rad, setpoint.insertion_mm)
        x0 = x_cc if self._x is None else self._x + (x_cc - self._x_cc)
        lower, upper = self._bounds(setpoint.insertion_mm)
        solution = self.inverse.solve(target_tip_mm, x0, setpoint.insertion_mm, lower, upper)
        x, _ = self.limiter.limit(solution.x)
        tendons = tendons_from_pulls(x[:2], self.workspace.pretension_mm)
        predicted = self.model.move_to(tendons, x[2])
        self._x, self._x_cc = x, x_cc
        return TendonCommand(tendons, float(x[2]), predicted, solution.limited)

    def _bounds(self, insertion_mm: float) -> tuple[np.ndarray, np.ndarray]:
        """The limiter's box, with the free length within max_insertion_offset_mm of the set-point's
        (or, when the rate limit cannot get there this cycle, as close to it as the rate allows)."""
        lower, upper = self.limiter.bounds()
        low = max(lower[2], insertion_mm - self.max_insertion_offset_mm)
        high = min(upper[2], insertion_mm + self.max_insertion_offset_mm)
        if low > high:
            low = high = min(max(insertion_mm, lower[2]), upper[2])
        lower[2], upper[2] = low, high
        return lower, upper
