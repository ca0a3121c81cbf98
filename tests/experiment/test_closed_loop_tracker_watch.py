"""The tracker watch of a closed-loop run, on the virtual testbed in simulated time.

Tracker loss is a sample gap longer than tracker.loss_timeout_s, counted from the start of the
run until the first valid tip: a tool reported MISSING in the first frames (tracker dropout) is
not yet a loss, a tool missing for longer than the timeout is, and ends with every axis stopped.
"""
import math

import pytest

from control import Articulation, make_controller
from control.trajectories import point_to_point
from crest.config import load_testbed_config
from crest.driver import SafetyStop
from crest.exit_codes import ExitCode
from crest.experiment.controlled_run import run_with_controller
from crest.experiment.workspace_from_config import limits_for, workspace_for
from crest.session import TRACKER_RATE_HZ, SessionOptions, open_session
from model import CatheterParams
from sim_backend.tracker import TrackerFault

CONFIG = load_testbed_config()
PARAMS = CatheterParams.from_toml()
WORKSPACE, LIMITS = workspace_for(CONFIG, PARAMS), limits_for(CONFIG)
PERIOD_S = CONFIG.sync.period_s
LOSS_TIMEOUT_S = CONFIG.tracker.loss_timeout_s
HOME = Articulation(0.0, 0.0, CONFIG.insertion_axis.home_position_mm)
STOPPED_STATES = {"QUICK_STOP_ACTIVE", "SWITCH_ON_DISABLED", "FAULT"}
FIRST_FRAMES_MISSING_S = 0.1        # well inside loss_timeout_s (0.25 s)


def bend_to_45_deg():
    return point_to_point(WORKSPACE, LIMITS, waypoints=[Articulation(math.pi / 4, 0.0, 60.0)],
                          tendon_velocity_mm_s=6.0, tendon_acceleration_mm_s2=60.0, insertion_velocity_mm_s=8.0,
                          insertion_acceleration_mm_s2=60.0, hold_s=0.5, period_s=PERIOD_S, start=HOME)


def test_a_tool_missing_in_the_first_frames_is_not_yet_tracker_loss():
    trajectory = bend_to_45_deg()
    controller = make_controller("dahl+fb", WORKSPACE, LIMITS, PERIOD_S, loss_timeout_s=LOSS_TIMEOUT_S)
    with open_session(SessionOptions(realtime=False, in_process=True)) as session:
        session.testbed.home()
        tracker = session.backend.virtual.tracker
        tracker.inject(TrackerFault.MISSING_TOOL)

        def tool_back_after_the_first_frames(cycle):
            if cycle * PERIOD_S >= FIRST_FRAMES_MISSING_S:
                tracker.clear(TrackerFault.MISSING_TOOL)

        result = run_with_controller(session, trajectory, controller, closed_loop=True,
                                     on_cycle=tool_back_after_the_first_frames)
        assert session.testbed.safety_stop is None
    assert result.cycles == len(trajectory)
    assert result.tracker_frames - result.tip_samples >= FIRST_FRAMES_MISSING_S * TRACKER_RATE_HZ - 1


def test_a_tool_missing_from_the_start_for_longer_than_the_timeout_stops_every_axis():
    trajectory = bend_to_45_deg()
    controller = make_controller("dahl+fb", WORKSPACE, LIMITS, PERIOD_S, loss_timeout_s=LOSS_TIMEOUT_S)
    cycles = []
    with open_session(SessionOptions(realtime=False, in_process=True)) as session:
        session.testbed.home()
        session.backend.virtual.tracker.inject(TrackerFault.MISSING_TOOL)
        with pytest.raises(SafetyStop) as stop:
            run_with_controller(session, trajectory, controller, closed_loop=True, on_cycle=cycles.append)
        states = {name: drive.state.name for name, drive in session.backend.virtual.drives.drives.items()}
    assert (stop.value.exit_code, stop.value.axis) == (ExitCode.TRACKER_LOST, "tracker")
    age_s = float(str(stop.value).split("no valid tip sample for ")[1].split(" s")[0])
    assert LOSS_TIMEOUT_S < age_s <= LOSS_TIMEOUT_S + 2 * PERIOD_S
    assert len(cycles) <= (LOSS_TIMEOUT_S + 2 * PERIOD_S) / PERIOD_S
    assert set(states.values()) <= STOPPED_STATES, states


def test_a_closed_loop_run_without_a_tracker_is_refused_before_anything_moves():
    controller = make_controller("dahl+fb", WORKSPACE, LIMITS, PERIOD_S)
    with open_session(SessionOptions(realtime=False, in_process=True, tracker=False)) as session:
        session.testbed.home()
        before = session.testbed.positions()
        with pytest.raises(ValueError, match="needs the tip tracker"):
            run_with_controller(session, bend_to_45_deg(), controller, closed_loop=True)
        assert session.testbed.positions() == before
        assert session.testbed.safety_stop is None
