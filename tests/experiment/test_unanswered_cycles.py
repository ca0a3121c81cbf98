"""A drive whose answers to a few SYNCs never come (frames lost) does not stop a run: the run counts
those cycles (RunResult.unanswered_cycles, printed by `crest run` and the bench), and each such
row leaves that axis' cells empty (crest.experiment.recorder)."""
from dataclasses import replace

import numpy as np

from control import Articulation, make_controller
from crest.config import load_testbed_config
from crest.experiment.builtin_trajectories import BuiltinOptions, builtin_trajectory
from crest.cli.run_command import _report
from crest.experiment.controlled_run import RunResult, run_with_controller
from crest.experiment.recorder import ExperimentRecorder
from crest.experiment.tip_coverage import TipCoverage
from crest.experiment.workspace_from_config import limits_for, workspace_for
from crest.log import read_log
from crest.session import SessionOptions, open_session
from model import CatheterParams

CONFIG = load_testbed_config()
PARAMS = CatheterParams.from_toml()
WORKSPACE, LIMITS = workspace_for(CONFIG, PARAMS), limits_for(CONFIG)
PERIOD_S = CONFIG.sync.period_s
HOME = Articulation(0.0, 0.0, CONFIG.insertion_axis.home_position_mm)
LOST_SYNCS = range(20, 23)          # the run's SYNCs whose TPDO1 from tendon2 is lost


def test_lost_answers_are_counted_and_their_cells_left_empty(tmp_path):
    trajectory = builtin_trajectory("circle", WORKSPACE, LIMITS, BuiltinOptions(articulation_deg=90.0, periods=0.1),
                                    PERIOD_S, HOME)
    with open_session(SessionOptions(realtime=False, in_process=True)) as session:
        session.testbed.home()
        process_data = session.backend.virtual.drives.drive("tendon2")._process_data
        transmit = process_data.transmit_on_sync
        syncs = []

        def losing_some():
            syncs.append(None)
            if len(syncs) - 1 not in LOST_SYNCS:
                transmit()

        recorder = ExperimentRecorder(session, tmp_path / "run.csv", PARAMS, source="test")
        process_data.transmit_on_sync = losing_some
        try:
            result = run_with_controller(session, trajectory, make_controller("cc", WORKSPACE, LIMITS, PERIOD_S),
                                         recorder=recorder)
        finally:
            process_data.transmit_on_sync = transmit
            recorder.close()
    log = read_log(tmp_path / "run.csv")
    empty = np.isnan(log.tendon_pos_mm[:, 1])
    # each lost answer, and after the last one a cycle that cannot tell the late answer from the new one
    assert len(LOST_SYNCS) <= result.unanswered_cycles <= len(LOST_SYNCS) + 1
    assert int(empty.sum()) == result.unanswered_cycles and result.cycles == len(log) == len(trajectory)
    assert np.isfinite(np.delete(log.tendon_pos_mm, 1, axis=1)).all() and np.isfinite(log.insertion_pos_mm).all()


def test_crest_run_names_the_cycles_without_every_answer_in_its_summary_line(capsys):
    result = RunResult(cycles=500, tip_samples=200, tracker_frames=200, rms_tip_error_mm=0.5, log_path=None,
                       tip_coverage=TipCoverage(None), command_process=False, held_cycles=0, unanswered_cycles=4)
    _report(result)
    line = capsys.readouterr().out
    assert line.startswith("ran 500 cycles; 4 cycles without every drive's answer in time")
    _report(replace(result, unanswered_cycles=0))
    assert "answer" not in capsys.readouterr().out
