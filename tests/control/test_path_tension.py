"""The tension a planned path needs, from the controller's model, and the jog's tension governor."""
import math

import numpy as np
import pytest

from control import Articulation, MotionLimits, Workspace
from control.path_tension import (DEFAULT_TENSION_MARGIN, TensionLimitError, check_path_tension,
                                  forecast_path_tension)
from control.tension_governor import TensionGovernor
from control.trajectories import articulation_sweep

MAX_TENSION_N = 40.0          # configs/testbed.toml [axis_defaults.tendon].max_tension_n
PRETENSION_MM = 0.005         # configs/testbed.toml [coordination].pretension_mm
NAMES = ("tendon1", "tendon2", "tendon3", "tendon4")


def sweep_forecast(params, degrees: float, free_length_mm: float):
    workspace = Workspace.from_params(params, pretension_mm=PRETENSION_MM)
    start = Articulation(0.0, 0.0, free_length_mm)
    path = articulation_sweep(workspace, MotionLimits(), angle_rad=math.radians(degrees), velocity_rad_s=0.6,
                              acceleration_rad_s2=2.0, hold_s=0.5, start=start)
    straight = np.full((1, 4), PRETENSION_MM)
    return forecast_path_tension(params, np.vstack([straight, path.tendon_mm]),
                                 np.concatenate([[free_length_mm], path.insertion_mm]))


def test_the_paper_sweep_to_180_deg_at_the_working_free_length_needs_less_than_the_limit(params):
    forecast = sweep_forecast(params, 180.0, params.free_length_mm)
    # moment balance at the base: EI theta / (r L) = 900 * pi / (2.5 * 80) = 14.1 N, plus the capstan friction
    assert 14.1 < forecast.peak_n[0] < MAX_TENSION_N / (1.0 + DEFAULT_TENSION_MARGIN)
    assert forecast.peak_n[2] < 2.0              # the antagonist is paid out, not fighting
    check_path_tension(forecast, [MAX_TENSION_N] * 4, NAMES, "sweep")


def test_the_same_bend_at_the_homed_free_length_needs_four_times_the_tension_and_is_refused(params):
    long = sweep_forecast(params, 120.0, 80.0).peak_n[0]
    short = sweep_forecast(params, 120.0, 20.0)
    assert short.peak_n[0] == pytest.approx(4.0 * long, rel=0.1)    # T ~ EI theta / (r L)
    assert short.peak_n[0] > MAX_TENSION_N
    with pytest.raises(TensionLimitError, match=r"needs 4\d\.\d N on tendon1 .*max_tension_n 40 N"):
        check_path_tension(short, [MAX_TENSION_N] * 4, NAMES, "sweep")


def test_the_governor_slows_linearly_from_70_to_90_percent_of_the_limit():
    governor = TensionGovernor((MAX_TENSION_N,) * 4)
    assert governor.speed_scale([20.0, 1.0, 1.0, 1.0]) == 1.0
    assert governor.speed_scale([32.0, 1.0, 1.0, 1.0]) == pytest.approx(0.5)
    assert governor.speed_scale([39.0, 1.0, 1.0, 1.0]) == governor.min_speed_scale


def test_the_governor_refuses_only_motion_that_loads_a_tendon_near_its_limit():
    governor = TensionGovernor((MAX_TENSION_N,) * 4)
    load = [37.0, 1.0, 1.0, 1.0]
    here = (5.0, 0.0, -5.0, 0.0)
    assert governor.judge(load, here, (5.2, 0.0, -5.2, 0.0), 20.0, 20.0).refused_tendon == 0    # pulling
    assert governor.judge(load, here, here, 20.0, 19.0).refused_tendon == 0                      # retracting
    assert governor.judge(load, here, (4.8, 0.0, -4.8, 0.0), 20.0, 20.0).refused_tendon is None  # paying out
    assert governor.judge(load, here, here, 20.0, 21.0).refused_tendon is None                   # extending
    assert governor.judge([30.0, 1.0, 1.0, 1.0], here, (5.2, 0.0, -5.2, 0.0), 20.0, 20.0).refused_tendon is None
