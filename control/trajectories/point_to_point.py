"""Point-to-point moves with velocity and acceleration limits (trapezoidal), holding at each point."""
from __future__ import annotations

from collections.abc import Sequence

from control.errors import ControlInputError, TrajectoryError
from control.inverse_kinematics import Articulation, articulation_from_tip
from control.motion_limits import MotionLimits
from control.trajectories.path_builder import PathBuilder, require_positive
from control.trajectories.trajectory import Trajectory
from control.workspace import Workspace


def point_to_point(workspace: Workspace, limits: MotionLimits = MotionLimits(), *,
                   waypoints: Sequence[Articulation | Sequence[float]], tendon_velocity_mm_s: float,
                   tendon_acceleration_mm_s2: float, insertion_velocity_mm_s: float | None = None,
                   insertion_acceleration_mm_s2: float | None = None, hold_s: float = 0.5,
                   period_s: float = 0.01, start: Articulation | None = None) -> Trajectory:
    """Visit each waypoint (an Articulation, or a tip position [mm] mapped by the constant-curvature
    inverse) on a straight line in (bend, free length), segments "move i" and "hold i" (i from 1).

    A move is one synchronised trapezoid: the bend vector at most v_t/r in norm, so no tendon
    faster than tendon_velocity_mm_s (likewise for acceleration), the free length at most
    insertion_velocity_mm_s (default: the configured maximum).
    """
    require_positive(tendon_velocity_mm_s=tendon_velocity_mm_s, tendon_acceleration_mm_s2=tendon_acceleration_mm_s2)
    if len(waypoints) == 0:
        raise TrajectoryError("point_to_point needs at least one waypoint")
    r = workspace.tendon_offset_mm
    path = PathBuilder(workspace, limits, period_s, start)
    for i, waypoint in enumerate(waypoints, start=1):
        if not isinstance(waypoint, Articulation):
            try:
                waypoint = articulation_from_tip(waypoint)
            except ControlInputError as exc:
                raise TrajectoryError(f"waypoint {i}: {exc}") from exc
        problem = workspace.violation(waypoint)
        if problem is not None:
            raise TrajectoryError(f"waypoint {i} is outside the workspace: {problem}")
        path.line(waypoint.bend_rad, waypoint.insertion_mm, f"move {i}",
                  bend_velocity_rad_s=tendon_velocity_mm_s / r, bend_acceleration_rad_s2=tendon_acceleration_mm_s2 / r,
                  insertion_velocity_mm_s=insertion_velocity_mm_s,
                  insertion_acceleration_mm_s2=insertion_acceleration_mm_s2)
        path.hold(hold_s, f"hold {i}")
    return path.build()
