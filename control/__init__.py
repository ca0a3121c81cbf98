"""Control of the CREST catheter: trajectories, inverse kinematics, the cc / dahl / dahl+fb
controllers and the tip/friction estimator. Imports only `model` (and numpy, scipy, filterpy)."""
from control.controllers import (CONTROLLER_NAMES, ConstantCurvatureController, Controller, DahlFeedback,
                                 DahlFeedforward, make_controller)
from control.errors import ControlInputError, TrackerLostError, TrajectoryError
from control.inverse_kinematics import (Articulation, articulation_from_pitch_yaw, articulation_from_tip,
                                        tendons_from_articulation, tip_from_articulation)
from control.motion_limits import MotionLimits
from control.setpoint import SetPoint
from control.state_estimator import SampleStatus, TipEstimator
from control.tendon_command import TendonCommand
from control.tip_measurement import TipMeasurement
from control.workspace import Workspace

__all__ = ["Articulation", "CONTROLLER_NAMES", "ConstantCurvatureController", "ControlInputError", "Controller",
           "DahlFeedback", "DahlFeedforward", "MotionLimits", "SampleStatus", "SetPoint", "TendonCommand",
           "TipEstimator", "TipMeasurement", "TrackerLostError", "TrajectoryError", "Workspace",
           "articulation_from_pitch_yaw", "articulation_from_tip", "make_controller", "tendons_from_articulation",
           "tip_from_articulation"]
