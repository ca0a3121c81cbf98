"""What the driver raises. Every message names the axis, what failed and what to do.

``DriveError`` and its kinds are failures of one step (boot, an SDO request, a state change,
a refused command); each carries the process exit code it stands for. ``SafetyStop`` is raised
after the testbed has been stopped: every axis was quick-stopped and the stop callbacks ran.
"""

from __future__ import annotations

from dataclasses import dataclass

from crest.exit_codes import ExitCode


class DriveError(RuntimeError):
    """A driver step failed on ``axis`` (None: not one axis, e.g. the bus)."""

    exit_code = ExitCode.ERROR

    def __init__(self, axis: str | None, message: str) -> None:
        self.axis = axis
        super().__init__(f"{axis}: {message}" if axis else message)


class BootError(DriveError):
    """The boot sequence could not bring an axis up (no boot-up, no process data, ...)."""


class IdentityMismatch(DriveError):
    """The drive on the bus is not the device the configuration's EDS describes."""

    exit_code = ExitCode.CONFIG


class ReadBackMismatch(DriveError):
    """A value written by SDO (parameter or PDO mapping) reads back different."""


class SdoFailure(DriveError):
    """An SDO request was aborted by the drive or not answered in time."""

    exit_code = ExitCode.SDO_FAILURE


class DriveTimeout(DriveError):
    """An axis did not reach what it was commanded to within its time limit."""


class HomingFailed(DriveError):
    """The drive reported a homing error (statusword bit 13 in homing mode)."""


class MotionRefused(DriveError):
    """A command outside the axis limits; refused before anything moved."""


class Terminated(KeyboardInterrupt):
    """SIGTERM arrived: stop exactly as for Ctrl-C, with its own exit code (TERMINATED).

    A KeyboardInterrupt, so every place that turns Ctrl-C into a stop of every axis does the same
    for SIGTERM; the CLI's signal handler raises it in the main thread.
    """


@dataclass(frozen=True)
class StopCause:
    """Why the testbed stopped: the exit code, the axis (or ``bus``, ``tracker``, None) and the reason."""

    exit_code: ExitCode
    axis: str | None
    reason: str

    @property
    def line(self) -> str:
        where = f"{self.axis}: " if self.axis else ""
        return f"safety stop ({self.exit_code.name}): {where}{self.reason}; all axes were quick-stopped"


class SafetyStop(Exception):
    """The testbed was stopped: every axis quick-stopped and disabled, stop callbacks run.

    ``exit_code`` is the process exit code for the cause, ``axis`` the axis (or ``bus``,
    ``tracker``; None for Ctrl-C or an exception), ``str()`` one line naming both.
    """

    def __init__(self, cause: StopCause) -> None:
        self.cause = cause
        self.exit_code = cause.exit_code
        self.axis = cause.axis
        super().__init__(cause.line)
