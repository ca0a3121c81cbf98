"""The CANopen master for the five CiA 402 axes of the CREST testbed, with coordination and safety.

Entry point: ``Testbed(bus, config, clock=None)`` (testbed.py). ``emergency_stop`` quick-stops
every drive from another process.
"""

from crest.driver.axis_targets import AXIS_ORDER, AxisTargets
from crest.driver.cia402 import Cia402State, OperationMode
from crest.driver.clock import Clock, MonotonicClock, SteppedClock
from crest.driver.cycle_runner import CycleSample
from crest.driver.emergency_stop import emergency_stop
from crest.driver.errors import (
    BootError,
    DriveError,
    DriveTimeout,
    HomingFailed,
    IdentityMismatch,
    MotionRefused,
    ReadBackMismatch,
    SafetyStop,
    SdoFailure,
    StopCause,
    Terminated,
)
from crest.driver.testbed import AxisStatus, BootReport, Testbed

__all__ = [
    "AXIS_ORDER",
    "AxisStatus",
    "AxisTargets",
    "BootError",
    "BootReport",
    "Cia402State",
    "Clock",
    "CycleSample",
    "DriveError",
    "DriveTimeout",
    "HomingFailed",
    "IdentityMismatch",
    "MonotonicClock",
    "MotionRefused",
    "OperationMode",
    "ReadBackMismatch",
    "SafetyStop",
    "SdoFailure",
    "SteppedClock",
    "StopCause",
    "Terminated",
    "Testbed",
    "emergency_stop",
]
