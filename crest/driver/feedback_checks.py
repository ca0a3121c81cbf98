"""What in one SYNC cycle's TPDO1 of an axis is a reason to stop.

- TPDO1 of the wrong length (the mapping is not what was verified at boot);
- an axis that must be enabled is not: FAULT (the drive stopped itself) or any other state
  (someone else commanded it, e.g. ``crest estop`` from another terminal);
- statusword bit 13 in profile position or cyclic synchronous position mode: the drive's
  following error (|demand - actual| > 0x6065) is active;
- in cyclic synchronous position mode, on the host too: the position actual sampled at this
  SYNC lags the target latched one SYNC earlier by more than following_error_window_mm;
- |tension| from torque actual above max_tension_n.
"""

from __future__ import annotations

from crest.driver import cia402
from crest.driver.cia402 import Cia402State, OperationMode
from crest.driver.drive_axis import DriveAxis
from crest.driver.errors import StopCause
from crest.driver.stop_causes import following_error_cause, tension_cause
from crest.exit_codes import ExitCode

_FOLLOWING_ERROR_MODES = (OperationMode.PROFILE_POSITION, OperationMode.CYCLIC_SYNC_POSITION)


def feedback_fault(axis: DriveAxis, latched_target_counts: int | None) -> StopCause | None:
    """The first problem in the axis' latest TPDO1, or None.

    ``latched_target_counts``: the CSP target the drive latched at the previous SYNC (None
    outside cyclic synchronous position mode).
    """
    if axis.tpdo_error is not None:
        return StopCause(ExitCode.ERROR, axis.name, f"{axis.tpdo_error}; the drive's TPDO1 changed since boot")
    statusword = axis.statusword
    state = cia402.state_from_statusword(statusword)
    if axis.must_be_enabled and state is not Cia402State.OPERATION_ENABLED:
        if state in (Cia402State.FAULT, Cia402State.FAULT_REACTION_ACTIVE):
            return StopCause(ExitCode.EMCY, axis.name, f"drive entered {state} (statusword 0x{statusword:04X})")
        return StopCause(ExitCode.ERROR, axis.name, f"drive left OPERATION ENABLED and is {state} without a command "
                                                    "from this host (crest estop, or the drive stopped itself)")
    if state is Cia402State.OPERATION_ENABLED and axis.mode in _FOLLOWING_ERROR_MODES \
            and statusword & cia402.FOLLOWING_ERROR:
        return following_error_cause(axis.name, f"the drive reports it (statusword 0x{statusword:04X}); "
                                                "check the axis is free to move")
    if latched_target_counts is not None:
        lag_mm = axis.config.counts_to_mm(latched_target_counts - axis.position_counts)
        if abs(lag_mm) > axis.config.following_error_window_mm:
            return following_error_cause(axis.name, f"position lags the set-point by {lag_mm:+.3f} mm "
                                                    f"(window {axis.config.following_error_window_mm:g} mm)")
    tension_n = axis.tension_n
    if abs(tension_n) > axis.config.max_tension_n:
        return tension_cause(axis.name, tension_n, axis.config.max_tension_n)
    return None
