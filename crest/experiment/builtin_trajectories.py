"""The builtin trajectories of `crest run builtin:NAME`: the paper's scenarios."""
from __future__ import annotations

import math
from dataclasses import dataclass

from control import Articulation, MotionLimits, Workspace
from control.trajectories import (Trajectory, articulation_sweep, circle, history_scenario,
                                  insertion_at_articulation)

BUILTINS = ("sweep", "circle", "insertion", "history")
ARTICULATION_VELOCITY_RAD_S = 0.6
ARTICULATION_ACCELERATION_RAD_S2 = 2.0
INSERTION_VELOCITY_MM_S = 5.0
INSERTION_ACCELERATION_MM_S2 = 20.0


@dataclass(frozen=True)
class BuiltinOptions:
    articulation_deg: float = 90.0
    plane_deg: float = 0.0
    insertion_mm: float | None = None    # free length of sweep/history/circle, or insertion's target
    periods: float = 1.0                 # sweeps (a whole number), circle turns (> 0)
    circle_period_s: float = 8.0


def builtin_start(name: str, workspace: Workspace, options: BuiltinOptions) -> Articulation:
    """Where the scenario `name` starts: straight, at the free length it runs at.

    The paper's scenarios bend to 180-270 deg, and the tension a bend needs grows as 1/L
    (control.path_tension): at the homed free length of the insertion axis (20 mm) 120 deg already
    needs the 40 N tendon limit. So sweep, history and circle run at --insertion-mm, by default
    at the catheter's working free length (configs/catheter.toml free_length_mm, 80 mm, inside the
    insertion range: `workspace.home_insertion_mm`); the insertion scenario starts there and
    moves to --insertion-mm. The run extends the catheter to this start after homing.
    """
    if name != "insertion" and options.insertion_mm is not None:
        return Articulation(0.0, 0.0, float(options.insertion_mm))
    return workspace.home


def builtin_trajectory(name: str, workspace: Workspace, limits: MotionLimits, options: BuiltinOptions,
                       period_s: float, start: Articulation) -> Trajectory:
    """The trajectory `name` from `start`; bad options raise TrajectoryError before anything moves."""
    if not (math.isfinite(options.periods) and options.periods > 0):
        raise ValueError(f"periods must be a number > 0 (sweeps or circle turns), got {options.periods!r}")
    if name == "sweep" and options.periods != int(options.periods):
        raise ValueError(f"builtin:sweep runs whole sweeps; periods must be a whole number, got {options.periods!r}")
    theta = math.radians(options.articulation_deg)
    plane = math.radians(options.plane_deg)
    common = dict(period_s=period_s, start=start)
    if name == "sweep":   # to the articulation and back, `periods` times (each ends where it began)
        one = articulation_sweep(workspace, limits, angle_rad=theta, plane_rad=plane,
                                 velocity_rad_s=ARTICULATION_VELOCITY_RAD_S,
                                 acceleration_rad_s2=ARTICULATION_ACCELERATION_RAD_S2, hold_s=0.5, back=True,
                                 **common)
        return one.repeated(int(options.periods))
    if name == "circle":
        return circle(workspace, limits, articulation_rad=theta, circle_period_s=options.circle_period_s,
                      turns=options.periods, start_plane_rad=plane, insertion_mm=options.insertion_mm,
                      lead_in_velocity_rad_s=ARTICULATION_VELOCITY_RAD_S,
                      lead_in_acceleration_rad_s2=ARTICULATION_ACCELERATION_RAD_S2, **common)
    if name == "insertion":
        target = options.insertion_mm if options.insertion_mm is not None else start.insertion_mm + 20.0
        return insertion_at_articulation(workspace, limits, articulation_rad=theta, plane_rad=plane,
                                         insertion_to_mm=target, insertion_velocity_mm_s=INSERTION_VELOCITY_MM_S,
                                         insertion_acceleration_mm_s2=INSERTION_ACCELERATION_MM_S2,
                                         articulation_velocity_rad_s=ARTICULATION_VELOCITY_RAD_S,
                                         articulation_acceleration_rad_s2=ARTICULATION_ACCELERATION_RAD_S2,
                                         **common)
    if name == "history":
        return history_scenario(workspace, limits, articulation_rad=theta, plane_rad=plane,
                                velocity_rad_s=ARTICULATION_VELOCITY_RAD_S,
                                acceleration_rad_s2=ARTICULATION_ACCELERATION_RAD_S2, **common)
    raise ValueError(f"unknown builtin trajectory 'builtin:{name}'; choose one of "
                     + ", ".join(f"builtin:{n}" for n in BUILTINS))
