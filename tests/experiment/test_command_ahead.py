"""A controller that ignores what was measured computes its next command while the drives answer
the SYNC (crest.experiment.controlled_run): the same commands, the same rows, the same errors
as computed one after the other, only off the cycle's critical path."""
import can
import numpy as np
import pytest

from control import Articulation, ControlInputError, make_controller
from crest.config import load_testbed_config
from crest.experiment.builtin_trajectories import BuiltinOptions, builtin_trajectory
from crest.experiment.controlled_run import run_with_controller
from crest.experiment.workspace_from_config import limits_for, workspace_for
from crest.session import SessionOptions, open_session
from model import CatheterParams

CONFIG = load_testbed_config()
WORKSPACE, LIMITS = workspace_for(CONFIG, CatheterParams.from_toml()), limits_for(CONFIG)
PERIOD_S = CONFIG.sync.period_s
HOME = Articulation(0.0, 0.0, CONFIG.insertion_axis.home_position_mm)
SYNC_COB_ID = 0x80
TRAJECTORY = builtin_trajectory("circle", WORKSPACE, LIMITS, BuiltinOptions(articulation_deg=90.0, periods=0.25),
                                PERIOD_S, HOME)


class Events:
    """The run's order of events: ("command", SYNCs on the bus so far) and ("row", SYNC time)."""

    path = None

    def __init__(self, monitor):
        self.monitor = monitor
        self.syncs = 0
        self.events = []
        self.targets_mm = []

    def on_command(self):
        while (frame := self.monitor.recv(0.0)) is not None:
            self.syncs += frame.arbitration_id == SYNC_COB_ID
        self.events.append(("command", self.syncs))

    def write(self, sample, tip_mm, tip_ref_mm=None):
        self.events.append(("row", sample.t_s))
        self.targets_mm.append(sample.target_mm)


def run(controller, *, uses_feedback, fail_at=None):
    """Run TRAJECTORY through `controller` (its command raising ControlInputError at call `fail_at`)
    in simulated time; the Events, and the error the run raised (or None)."""
    controller.uses_feedback = uses_feedback
    command = controller.command
    with open_session(SessionOptions(realtime=False, in_process=True)) as session:
        session.testbed.home()
        events = Events(can.Bus(interface="virtual", channel=session.backend.virtual.channel))

        def observed(*args, **kwargs):
            events.on_command()
            if len([e for e in events.events if e[0] == "command"]) == fail_at:
                raise ControlInputError("the test's set-point is refused")
            return command(*args, **kwargs)

        controller.command = observed
        try:
            run_with_controller(session, TRAJECTORY, controller, recorder=events)
        except ControlInputError as error:
            return events, error
        finally:
            events.monitor.shutdown()
    return events, None


@pytest.fixture(scope="module")
def dahl_runs():
    return {mode: run(make_controller("dahl", WORKSPACE, LIMITS, PERIOD_S), uses_feedback=mode == "sequential")[0]
            for mode in ("ahead", "sequential")}


def test_the_next_command_is_computed_after_the_sync_is_sent_and_before_its_row(dahl_runs):
    events = dahl_runs["ahead"].events
    commands = [k for k, (kind, _) in enumerate(events) if kind == "command"]
    rows = [k for k, (kind, _) in enumerate(events) if kind == "row"]
    assert len(rows) == len(TRAJECTORY) and len(commands) == len(TRAJECTORY)
    syncs_before = events[commands[0]][1]     # (switching to cyclic mode takes a few SYNCs after it)
    for cycle, row in enumerate(rows[:-1]):
        kind, syncs = events[row - 1]
        assert kind == "command", f"cycle {cycle}: its row is not preceded by the next command"
        assert syncs > syncs_before, f"cycle {cycle}: the next command was computed before its SYNC was sent"
        assert cycle == 0 or syncs == syncs_before + 1, f"cycle {cycle}: one SYNC per cycle"
        syncs_before = syncs


def test_a_feedforward_controller_sends_the_same_commands_ahead_as_one_after_the_other(dahl_runs):
    sequential = dahl_runs["sequential"].events
    assert [kind for kind, _ in sequential[:4]] == ["command", "row", "command", "row"]
    np.testing.assert_array_equal(dahl_runs["ahead"].targets_mm, dahl_runs["sequential"].targets_mm)
    assert np.ptp(np.array(dahl_runs["ahead"].targets_mm)[:, 0]) > 0.5      # the tendons did move


@pytest.mark.parametrize("uses_feedback", [False, True])
def test_a_refused_command_ends_the_run_after_the_same_rows_either_way(uses_feedback):
    events, error = run(make_controller("cc", WORKSPACE, LIMITS, PERIOD_S), uses_feedback=uses_feedback,
                        fail_at=6)
    assert isinstance(error, ControlInputError)
    assert len(events.targets_mm) == 5
