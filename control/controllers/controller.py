"""The one interface every controller has: a set-point (and what was measured) in, a command out."""
from __future__ import annotations

import math
from abc import ABC, abstractmethod

import numpy as np

from control.errors import ControlInputError
from control.setpoint import SetPoint
from control.tendon_command import TendonCommand
from control.tip_measurement import TipMeasurement
from control.workspace import Workspace


class Controller(ABC):
    """Called once per SYNC period by the run loop.

    command(setpoint, tip, drive_tension_n): `tip` is the latest tracker sample (None when
    there is none this cycle), `drive_tension_n` the (4,) tendon tensions from the drives
    when available. Open-loop controllers ignore both. Returns the TendonCommand to send.
    reset(insertion_mm): forget all history; the catheter is straight and unloaded, tendons at
    0 mm, at this free length (default: the workspace's home free length).
    uses_feedback: False when the command ignores `tip` and `drive_tension_n`; the run loop
    then computes the next command while the drives answer the current SYNC.
    """

    name: str
    uses_feedback: bool = False

    @abstractmethod
    def command(self, setpoint: SetPoint, tip: TipMeasurement | None = None,
                drive_tension_n: np.ndarray | None = None) -> TendonCommand:
        ...

    @abstractmethod
    def reset(self, insertion_mm: float | None = None) -> None:
        ...


def checked_setpoint(setpoint: SetPoint, workspace: Workspace) -> SetPoint:
    """The set-point, or ControlInputError (before any state changes) if it is not finite or outside."""
    tip = np.asarray(setpoint.tip_mm, dtype=float)
    if tip.shape != (3,) or not np.isfinite(tip).all():
        raise ControlInputError(f"set-point at t={setpoint.t_s} s: target tip must be 3 finite coordinates in mm, "
                                f"got {setpoint.tip_mm!r}")
    if not math.isfinite(setpoint.t_s):
        raise ControlInputError(f"set-point time must be finite, got {setpoint.t_s!r}")
    workspace.check(setpoint.articulation, f"set-point at t={setpoint.t_s} s")
    return setpoint
