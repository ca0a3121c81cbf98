"""`dahl+fb`: the Dahl feedforward plus an outer loop on the filtered tip error.

Each cycle, in this order:
1. fuse the newest tracker sample (and drive tensions) into the estimator, whose prediction
   is the model's after the previous command: the sample shows the response to that command;
2. stop (TrackerLostError) when no valid sample has arrived for longer than loss_timeout_s;
3. integrate the filtered error e = target_k-1 - tip_hat into the correction c, starting from
   the correction the last command realised in the model (TipCorrection, anti-windup);
4. aim the feedforward at target_k + c and send what it returns;
5. drive the friction-scaled model with the same command and let the estimator predict.
"""
from __future__ import annotations

import numpy as np

from control.controllers.controller import Controller, checked_setpoint
from control.controllers.dahl_feedforward import DahlFeedforward
from control.errors import TrackerLostError
from control.friction_sensitivity import FrictionSensitivity
from control.motion_limits import MotionLimits
from control.setpoint import SetPoint
from control.state_estimator import TipEstimator
from control.tendon_command import TendonCommand
from control.tip_correction import TipCorrection
from control.tip_measurement import TipMeasurement
from control.workspace import Workspace


class DahlFeedback(Controller):
    """feedforward: the DahlFeedforward it wraps; estimator: TipEstimator (tip_mm, friction_scale,
    counts of gated samples); correction: TipCorrection. loss_timeout_s: configs/testbed.toml
    [tracker].loss_timeout_s. The command's predicted_tip_mm is the estimator's prediction."""

    name = "dahl+fb"
    uses_feedback = True

    def __init__(self, workspace: Workspace, limits: MotionLimits = MotionLimits(), period_s: float = 0.01, *,
                 n_elements: int = 20, loss_timeout_s: float = 0.25, estimator: TipEstimator | None = None,
                 correction: TipCorrection | None = None):
        if not loss_timeout_s > 0:
            raise ValueError(f"loss_timeout_s must be > 0, got {loss_timeout_s!r}")
        self.workspace = workspace
        self.period_s = float(period_s)
        self.loss_timeout_s = float(loss_timeout_s)
        self.feedforward = DahlFeedforward(workspace, limits, period_s, n_elements=n_elements)
        self.sensitivity = FrictionSensitivity(workspace.params, n_elements)
        self.estimator = TipEstimator() if estimator is None else estimator
        self.correction = TipCorrection(period_s) if correction is None else correction
        self.reset()

    def reset(self, insertion_mm: float | None = None) -> None:
        insertion_mm = self.workspace.home_insertion_mm if insertion_mm is None else insertion_mm
        self.feedforward.reset(insertion_mm)
        self.sensitivity.reset(insertion_mm)
        self.estimator.reset()
        self.correction.reset()
        self._previous_target: np.ndarray | None = None
        self._realised_mm = np.zeros(3)

    def command(self, setpoint: SetPoint, tip: TipMeasurement | None = None,
                drive_tension_n: np.ndarray | None = None) -> TendonCommand:
        setpoint = checked_setpoint(setpoint, self.workspace)
        now_s = setpoint.t_s
        if self._previous_target is None:
            self.estimator.reset(time_s=now_s)
        else:
            if tip is not None:
                self.estimator.update_tip(tip, now_s)
            if drive_tension_n is not None:
                self.estimator.update_tension(drive_tension_n)
            silent_s = now_s - self.estimator.last_valid_time_s
            if silent_s > self.loss_timeout_s:
                counts = {s.value: n for s, n in self.estimator.counts.items() if n}
                raise TrackerLostError(f"no valid tip sample for {silent_s:.3f} s at t={now_s:.3f} s (loss timeout "
                                       f"{self.loss_timeout_s} s; samples so far: {counts}): stop the closed-loop "
                                       f"run and check the tracker")
            self.correction.update(self._previous_target - self.estimator.tip_mm, self._realised_mm)
        sent = self.feedforward.command_toward(setpoint.tip_mm + self.correction.correction_mm, setpoint)
        prediction = self.sensitivity.advance(sent.tendon_mm, sent.insertion_mm, sent.predicted_tip_mm,
                                              self.feedforward.model.drive_tension_n)
        self.estimator.predict(prediction, self.period_s)
        self._previous_target = setpoint.tip_mm
        self._realised_mm = sent.predicted_tip_mm - setpoint.tip_mm
        return TendonCommand(sent.tendon_mm, sent.insertion_mm, self.estimator.tip_mm, sent.saturated)
