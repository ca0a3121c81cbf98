"""`dahl`: friction-aware feedforward that inverts the Dahl catheter model online, open loop.

Each cycle: solve for the command the model predicts puts the tip on the target (DahlInverse),
warm-started from the previous solution moved by the constant-curvature increment of the
set-point, x0 = x_prev + (x_cc,k - x_cc,k-1); keep it inside the range and rate box; then drive
the model with the command actually sent. The model's friction state therefore follows the
catheter's own input history, and the hysteresis is compensated along the whole path,
reversals included.
"""
from __future__ import annotations

import numpy as np

from model import DahlCatheter

from control.command_limiter import CommandLimiter
from control.controllers.controller import Controller, checked_setpoint
from control.dahl_inverse import DahlInverse, InverseSolution
from control.inverse_kinematics import tendons_from_pulls
from control.motion_limits import MotionLimits
from control.setpoint import SetPoint
from control.tendon_command import TendonCommand
from control.tip_measurement import TipMeasurement
from control.workspace import Workspace


class DahlFeedforward(Controller):
    """model: the controller's DahlCatheter (workspace.params, n_elements), state = what was sent.
    last_solution: the InverseSolution of the last cycle (residual, evaluations) for logging."""

    name = "dahl"

    def __init__(self, workspace: Workspace, limits: MotionLimits = MotionLimits(), period_s: float = 0.01, *,
                 n_elements: int = 20, insertion_weight: float = 1e-3, tolerance_mm: float = 0.03):
        self.workspace = workspace
        self.model = DahlCatheter(workspace.params, n_elements)
        self.inverse = DahlInverse(self.model, workspace.pretension_mm, insertion_weight=insertion_weight,
                                   tolerance_mm=tolerance_mm)
        self.limiter = CommandLimiter(workspace, limits, period_s)
        self.last_solution: InverseSolution | None = None
        self._x: np.ndarray | None = None
        self._x_cc: np.ndarray | None = None

    def reset(self) -> None:
        self.model.reset()
        self.inverse.reset()
        self.limiter.reset(insertion_mm=self.model.free_length_mm)
        self.last_solution = None
        self._x = None
        self._x_cc = None

    def command(self, setpoint: SetPoint, tip: TipMeasurement | None = None,
                drive_tension_n: np.ndarray | None = None) -> TendonCommand:
        return self.command_toward(checked_setpoint(setpoint, self.workspace).tip_mm, setpoint)

    def command_toward(self, target_tip_mm, setpoint: SetPoint) -> TendonCommand:
        """The command for `target_tip_mm` (the set-point's tip, or a corrected one from feedback)."""
        x_cc = np.append(self.workspace.tendon_offset_mm * setpoint.articulation.bend_rad, setpoint.insertion_mm)
        x0 = x_cc if self._x is None else self._x + (x_cc - self._x_cc)
        lower, upper = self.limiter.bounds()
        solution = self.inverse.solve(target_tip_mm, x0, setpoint.insertion_mm, lower, upper)
        x, _ = self.limiter.limit(solution.x)
        tendons = tendons_from_pulls(x[:2], self.workspace.pretension_mm)
        predicted = self.model.move_to(tendons, x[2])
        self._x, self._x_cc, self.last_solution = x, x_cc, solution
        return TendonCommand(tendons, float(x[2]), predicted, solution.limited)
