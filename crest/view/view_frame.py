"""What one screen of the live view or the replay shows, independent of where it came from.

The live state (live_state.py) and the replay (replay_state.py) both produce a ViewFrame; the
page (page.py) draws any ViewFrame. Positions in mm in the catheter base frame (origin at the
support-tube exit, z out of the tube, x toward tendon 1), tensions in N, times in s.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class AxisRow:
    """One axis: its CiA 402 state ('' when not known, e.g. in a log), position and following error.

    ``position_mm`` is NaN when the drive's answer to this SYNC did not come (an empty log cell);
    the following error is then None.

    ``following_error_mm`` is the set-point latched one SYNC earlier minus the position actual
    sampled at this SYNC (the host's following-error check, feedback_checks.py); during a
    profile-position move (homing, a point move) the set-point is the move's goal.
    """

    axis: str
    state: str
    position_mm: float
    following_error_mm: float | None


@dataclass(frozen=True)
class StopReport:
    """A safety stop in plain words: the stop's line (it names the cause, its exit code and the
    axis when there is one), the process exit code, and when it happened."""

    line: str
    exit_code: int
    when: str

    def describe(self) -> str:
        return f"STOPPED {self.when} (exit code {self.exit_code}): {self.line}"


@dataclass(frozen=True)
class ViewFrame:
    """One screen. Arrays are empty (shape (0, 3) or (0,)) when there is nothing to draw."""

    t_s: float                                  # loop time of the newest sample shown
    backbone_mm: np.ndarray                     # (n, 3) the model's backbone from the measured positions
    tip_mm: np.ndarray | None                   # the tracker's tip (None: no valid sample)
    trail_mm: np.ndarray                        # (m, 3) recent tracker tips, oldest first
    reference_mm: np.ndarray                    # (k, 3) the run's reference tip path
    tension_t_s: np.ndarray                     # (w,) times of the tension window
    tension_n: np.ndarray                       # (w, 4) tendon tensions over the window
    max_tension_n: float                        # the configured limit (smallest of the tendon axes)
    axes: tuple[AxisRow, ...]
    status: str                                 # what runs: command, controller, progress
    tip_error_mm: float | None                  # |tip - reference| when both are known
    stop: StopReport | None = None
    notes: tuple[str, ...] = field(default_factory=tuple)
