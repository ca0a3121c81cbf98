"""Controllers by name, as `crest --controller cc|dahl|dahl+fb` chooses them."""
from __future__ import annotations

from control.controllers.constant_curvature import ConstantCurvatureController
from control.controllers.controller import Controller
from control.controllers.dahl_feedback import DahlFeedback
from control.controllers.dahl_feedforward import DahlFeedforward
from control.errors import ControlInputError
from control.motion_limits import MotionLimits
from control.workspace import Workspace

CONTROLLER_NAMES = ("cc", "dahl", "dahl+fb")


def make_controller(name: str, workspace: Workspace, limits: MotionLimits = MotionLimits(), period_s: float = 0.01,
                    *, n_elements: int = 20, loss_timeout_s: float = 0.25) -> Controller:
    """The controller called `name`; its model is workspace.params (e.g. from --catheter PARAMS.toml).

    n_elements applies to the Dahl model of `dahl` and `dahl+fb`; loss_timeout_s to `dahl+fb`.
    """
    if name == "cc":
        return ConstantCurvatureController(workspace, limits, period_s)
    if name == "dahl":
        return DahlFeedforward(workspace, limits, period_s, n_elements=n_elements)
    if name == "dahl+fb":
        return DahlFeedback(workspace, limits, period_s, n_elements=n_elements, loss_timeout_s=loss_timeout_s)
    raise ControlInputError(f"unknown controller {name!r}; choose one of {', '.join(CONTROLLER_NAMES)}")


__all__ = ["CONTROLLER_NAMES", "ConstantCurvatureController", "Controller", "DahlFeedback", "DahlFeedforward",
           "make_controller"]
