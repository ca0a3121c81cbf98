"""Per-cycle compute time of each controller, for `crest bench` (speed lives here, not in tests).

Each controller runs the demanding case of issue 5 (a circle at 180 deg articulation, with
friction) against a plant that is the nominal model; the plant's time is not counted, and
the tracker sample is the plant's tip every cycle.
"""
from __future__ import annotations

import math
import time

import numpy as np

from model import CatheterParams, DahlCatheter

from control.controllers import CONTROLLER_NAMES, make_controller
from control.motion_limits import MotionLimits
from control.tip_measurement import TipMeasurement
from control.trajectories import circle
from control.workspace import Workspace


def controller_cycle_times(params: CatheterParams | None = None, *, n_elements: int = 20, period_s: float = 0.01,
                           pretension_mm: float = 0.02, circle_period_s: float = 8.0,
                           controllers: tuple[str, ...] = CONTROLLER_NAMES) -> dict[str, dict[str, float]]:
    """{controller: {"median_us", "p95_us", "p99_us", "max_us", "median_fraction_of_period", "cycles"}}.

    The first cycle of each run (JIT loading, allocation) is left out.
    """
    params = CatheterParams.from_toml() if params is None else params
    workspace = Workspace.from_params(params, pretension_mm=pretension_mm)
    limits = MotionLimits()
    trajectory = circle(workspace, limits, articulation_rad=math.pi, circle_period_s=circle_period_s,
                        lead_in_velocity_rad_s=2.0, lead_in_acceleration_rad_s2=4.0, period_s=period_s)
    results = {}
    for name in controllers:
        controller = make_controller(name, workspace, limits, period_s, n_elements=n_elements)
        plant = DahlCatheter(params, n_elements)
        controller.reset()
        times_s = []
        for setpoint in trajectory:
            sample = TipMeasurement(plant.tip_mm, setpoint.t_s)
            start = time.perf_counter()
            command = controller.command(setpoint, sample)
            times_s.append(time.perf_counter() - start)
            plant.move_to(command.tendon_mm, command.insertion_mm)
        times_us = 1e6 * np.array(times_s[1:])
        results[name] = {"median_us": float(np.median(times_us)), "p95_us": float(np.percentile(times_us, 95)),
                         "p99_us": float(np.percentile(times_us, 99)), "max_us": float(times_us.max()),
                         "median_fraction_of_period": float(np.median(times_us) * 1e-6 / period_s),
                         "cycles": len(times_us)}
    return results
