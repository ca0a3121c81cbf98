"""`cc`: the constant-curvature inverse, open loop (the baseline every comparison is made against)."""
from __future__ import annotations

import numpy as np

from control.command_limiter import CommandLimiter
from control.controllers.controller import Controller, checked_setpoint
from control.inverse_kinematics import Articulation, tendons_from_pulls, tip_from_articulation
from control.motion_limits import MotionLimits
from control.setpoint import SetPoint
from control.tendon_command import TendonCommand
from control.tip_measurement import TipMeasurement
from control.workspace import Workspace


class ConstantCurvatureController(Controller):
    """Tendons u_k = r theta cos(phi_k - plane) + u0 and the set-point's free length, limited.

    The predicted tip is the constant-curvature tip of the command actually sent.
    """

    name = "cc"

    def __init__(self, workspace: Workspace, limits: MotionLimits = MotionLimits(), period_s: float = 0.01):
        self.workspace = workspace
        self.limiter = CommandLimiter(workspace, limits, period_s)

    def reset(self, insertion_mm: float | None = None) -> None:
        self.limiter.reset(insertion_mm=insertion_mm)

    def command(self, setpoint: SetPoint, tip: TipMeasurement | None = None,
                drive_tension_n: np.ndarray | None = None) -> TendonCommand:
        setpoint = checked_setpoint(setpoint, self.workspace)
        r = self.workspace.tendon_offset_mm
        wanted = np.append(r * setpoint.articulation.bend_rad, setpoint.insertion_mm)
        x, saturated = self.limiter.limit(wanted)
        sent = Articulation.from_bend(x[:2] / r, x[2])
        return TendonCommand(tendons_from_pulls(x[:2], self.workspace.pretension_mm), float(x[2]),
                             tip_from_articulation(sent, self.workspace.params), saturated)
