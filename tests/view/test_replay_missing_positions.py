"""Replaying a log in which a drive did not answer some SYNCs: the axis table shows no position for
that axis in those rows, and the backbone is drawn from its position filled from the measured rows."""
import math

import numpy as np

from crest.config import load_testbed_config
from crest.log import LogWriter, catheter_dict
from crest.view.model_backbone import ModelBackbone
from crest.view.page import _axis_table
from crest.view.replay_state import ReplayState

TENDON_OFFSET_MM = 2.5
FREE_LENGTH_MM = 60.0


def test_rows_without_an_answer_show_no_position_and_a_filled_backbone(tmp_path):
    path = tmp_path / "silent.csv"
    with LogWriter(path, catheter=catheter_dict(flexible_length_mm=100.0, tendon_offset_mm=TENDON_OFFSET_MM,
                                                outer_diameter_mm=6.0),
                   sample_rate_hz=100.0, source="replay test", tendon_force=True,
                   config=load_testbed_config().as_dict()) as writer:
        for i, pull_mm in enumerate([0.0, 1.0, math.nan, 3.0]):      # tendon 1 silent at row 2 (0.02 s)
            writer.write(0.01 * i, (pull_mm if i != 2 else 2.0, 0.0, 0.0, 0.0), FREE_LENGTH_MM,
                         (pull_mm, 0.0, 0.0, 0.0), FREE_LENGTH_MM, (1.0, 0.0, 59.0),
                         tendon_force_n=(math.nan if i == 2 else 5.0, 5.0, 5.0, 5.0))
    frame = ReplayState(path).frame_at(0.02)
    tendon1 = frame.axes[0]
    assert math.isnan(tendon1.position_mm) and tendon1.following_error_mm is None
    assert frame.axes[1].position_mm == 0.0 and frame.axes[1].following_error_mm == 0.0
    assert "<td>tendon1</td><td>not logged</td><td style='text-align:right'>no answer</td>" in _axis_table(frame)
    # the backbone of tendon 1 at 2 mm: halfway in time between 1 mm (0.01 s) and 3 mm (0.03 s)
    expected = ModelBackbone(TENDON_OFFSET_MM).points_mm((2.0, 0.0, 0.0, 0.0), FREE_LENGTH_MM)
    np.testing.assert_allclose(frame.backbone_mm, expected, rtol=0, atol=1e-9)
    assert np.isfinite(frame.backbone_mm).all()


def test_a_log_written_without_a_configuration_replays_without_a_tension_limit(tmp_path):
    """A sidecar whose config is null (a log from another writer) has no axis limits to show."""
    path = tmp_path / "bare.csv"
    with LogWriter(path, catheter=catheter_dict(flexible_length_mm=100.0, tendon_offset_mm=TENDON_OFFSET_MM,
                                                outer_diameter_mm=6.0),
                   sample_rate_hz=100.0, source="replay test") as writer:
        for i in range(3):
            writer.write(0.01 * i, (0.5 * i, 0.0, 0.0, 0.0), FREE_LENGTH_MM, (0.5 * i, 0.0, 0.0, 0.0),
                         FREE_LENGTH_MM, (1.0, 0.0, 59.0))
    state = ReplayState(path)
    assert math.isnan(state.max_tension_n)
    assert state.frame_at(0.02).axes[0].position_mm == 1.0
