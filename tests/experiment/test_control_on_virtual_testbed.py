"""The control claims, shown on the virtual testbed: drives, plant and tracker, cycle by cycle.

The plant (configs/virtual_plant.toml) differs from the controller's model by 10-20 % and one
unmodelled effect (gravity) is switched on. Runs use simulated time, with the tracker polled
fast enough that its samples are current.
"""
import math

import numpy as np
import pytest

from control import Articulation, make_controller
from control.trajectories import point_to_point
from crest.config import load_testbed_config
from crest.experiment.builtin_trajectories import BuiltinOptions, builtin_trajectory
from crest.experiment.controlled_run import run_with_controller
from crest.experiment.workspace_from_config import limits_for, workspace_for
from crest.session import SessionOptions, open_session
from model import CatheterParams

CONFIG = load_testbed_config()
PARAMS = CatheterParams.from_toml()
WORKSPACE, LIMITS = workspace_for(CONFIG, PARAMS), limits_for(CONFIG)
PERIOD_S = CONFIG.sync.period_s
HOME = Articulation(0.0, 0.0, CONFIG.insertion_axis.home_position_mm)


def session_options(**overrides):
    return SessionOptions(realtime=False, in_process=True, effects={"gravity": {}}, **overrides)


class ErrorLog:
    """Collects |tip - tip_ref| per cycle (NaN without a tip)."""

    path = None

    def __init__(self):
        self.errors = []
        self.tips = []

    def write(self, sample, tip_mm, tip_ref_mm=None):
        self.tips.append(np.full(3, np.nan) if tip_mm is None else np.array(tip_mm))
        self.errors.append(np.nan if tip_mm is None else float(np.linalg.norm(tip_mm - tip_ref_mm)))


def rms(values):
    values = np.asarray(values)
    values = values[~np.isnan(values)]
    return float(np.sqrt(np.mean(values ** 2)))


def run(trajectory, controller_name, **session_overrides):
    log = ErrorLog()
    controller = make_controller(controller_name, WORKSPACE, LIMITS, PERIOD_S)
    with open_session(session_options(**session_overrides)) as session:
        session.testbed.home()
        run_with_controller(session, trajectory, controller, recorder=log,
                            closed_loop=controller_name == "dahl+fb")
    return log


@pytest.fixture(scope="module")
def circle_errors():
    trajectory = builtin_trajectory("circle", WORKSPACE, LIMITS,
                                    BuiltinOptions(articulation_deg=180.0, insertion_mm=60.0), PERIOD_S, HOME)
    on_circle = trajectory.mask("circle")
    return {name: rms(np.array(run(trajectory, name).errors)[on_circle]) for name in ("cc", "dahl", "dahl+fb")}


def test_circle_at_180_deg_dahl_cuts_the_cc_error_by_60_percent_and_feedback_further(circle_errors):
    assert circle_errors["dahl"] <= 0.4 * circle_errors["cc"], circle_errors
    assert circle_errors["dahl+fb"] < circle_errors["dahl"], circle_errors


def reversal_offset(controller_name):
    """Tip at 90 deg reached from 0 deg and from 150 deg: the path-dependent offset."""
    target = Articulation(math.pi / 2, 0.0, 60.0)
    above = Articulation(math.radians(150.0), 0.0, 60.0)
    ends = []
    for waypoints in ([target], [above, target]):
        trajectory = point_to_point(WORKSPACE, LIMITS, waypoints=waypoints, tendon_velocity_mm_s=6.0,
                                    tendon_acceleration_mm_s2=60.0, insertion_velocity_mm_s=8.0,
                                    insertion_acceleration_mm_s2=60.0, hold_s=1.0, period_s=PERIOD_S, start=HOME)
        tips = np.array(run(trajectory, controller_name).tips)
        ends.append(np.nanmean(tips[-30:], axis=0))
    return float(np.linalg.norm(ends[0] - ends[1]))


def test_reversals_dahl_removes_most_of_the_path_dependent_offset():
    cc, dahl = reversal_offset("cc"), reversal_offset("dahl")
    assert cc > 3.0                      # friction makes the end point depend on the path
    assert dahl < 0.3 * cc, (cc, dahl)


def test_filter_tracks_the_true_tip_through_dropout_and_noise():
    trajectory = builtin_trajectory("circle", WORKSPACE, LIMITS,
                                    BuiltinOptions(articulation_deg=120.0, insertion_mm=60.0), PERIOD_S, HOME)
    controller = make_controller("dahl+fb", WORKSPACE, LIMITS, PERIOD_S)
    errors = []
    with open_session(session_options(tracker_noise_mm=0.3, tracker_dropout=0.2)) as session:
        session.testbed.home()

        def compare(_cycle):
            errors.append(np.linalg.norm(controller.estimator.tip_mm - session.backend.virtual.true_tip_mm()))

        run_with_controller(session, trajectory, controller, closed_loop=True, on_cycle=compare)
    assert rms(errors) < 1.0
