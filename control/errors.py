"""What control refuses, and why: errors a person can act on."""


class ControlInputError(ValueError):
    """A set-point, target or setting given to control is not finite or outside the workspace."""


class TrajectoryError(ControlInputError):
    """A trajectory is refused before anything runs: NaN, outside the workspace, or too fast."""


class TrackerLostError(RuntimeError):
    """No valid tip sample for longer than the loss timeout: a closed-loop run must stop."""
