"""Logs become recordings; inconsistent inputs are refused with an actionable message."""
import numpy as np
import pytest

from crest.gap.log_recordings import load_recordings
from crest.log import LogFormatError, LogWriter, catheter_dict
from model import CatheterParams
from model.gap.recording import Recording, RecordingError
from model.gap.simulation import Resolution, catheter_for


def write_log(path, angles=(0.0, 90.0, 180.0, 270.0), offset_mm=2.5):
    catheter = catheter_dict(flexible_length_mm=100.0, tendon_offset_mm=offset_mm, outer_diameter_mm=None,
                             tendon_angles_deg=angles)
    with LogWriter(path, catheter=catheter, sample_rate_hz=10.0, source="test") as writer:
        for k in range(5):
            writer.write(0.1 * k, [0.1 * k, 0, -0.1 * k, 0], 80.0, [0.1 * k, 0, -0.1 * k, 0], 80.0,
                         None if k == 2 else [k, 0.0, 80.0])
    return path


def test_log_becomes_a_recording_with_measured_positions_and_missing_tips(tmp_path):
    recording, = load_recordings([write_log(tmp_path / "a.csv")])
    assert recording.tendon_mm.shape == (5, 4) and recording.tendon_offset_mm == 2.5
    assert list(recording.valid) == [True, True, False, True, True]
    assert recording.outer_diameter_mm is None
    assert catheter_for(CatheterParams.from_toml(), [recording]).outer_diameter_mm > 2 * 2.5


def test_other_tendon_angles_are_refused(tmp_path):
    with pytest.raises(RecordingError, match="tendon_angles_deg"):
        load_recordings([write_log(tmp_path / "a.csv", angles=(45.0, 135.0, 225.0, 315.0))])


def test_logs_of_two_catheters_are_not_fitted_together(tmp_path):
    recordings = load_recordings([write_log(tmp_path / "a.csv"), write_log(tmp_path / "b.csv", offset_mm=3.0)])
    with pytest.raises(RecordingError, match="one catheter"):
        catheter_for(CatheterParams.from_toml(), recordings)


def test_recording_without_any_tip_is_refused():
    t = np.arange(5.0)
    with pytest.raises(RecordingError, match="no tip sample"):
        Recording("r", t, np.zeros((5, 4)), np.full(5, 80.0), np.full((5, 3), np.nan), None, 100.0, 2.5, None)


def test_training_data_is_capped_in_proportion():
    t = np.arange(0, 100.0, 0.01)
    recording = Recording("r", t, np.zeros((len(t), 4)), np.full(len(t), 80.0), np.zeros((len(t), 3)), None,
                          100.0, 2.5, None)
    prepared = Resolution(fit_rate_hz=10.0, max_fit_samples=600).prepare_training([recording, recording])
    assert [len(r) for r in prepared] == [300, 300]
    assert prepared[0].t_s[1] - prepared[0].t_s[0] == pytest.approx(0.1)


def test_positions_a_drive_did_not_answer_are_filled_for_the_model(tmp_path):
    path = tmp_path / "silent.csv"
    catheter = catheter_dict(flexible_length_mm=100.0, tendon_offset_mm=2.5, outer_diameter_mm=None)
    with LogWriter(path, catheter=catheter, sample_rate_hz=10.0, source="test", tendon_force=True) as writer:
        for k in range(5):
            silent = k in (2, 3)                        # tendon 1 and the insertion drive did not answer
            writer.write(0.1 * k, [0.1 * k, 0, 0, 0], 80.0, [np.nan if silent else 0.1 * k, 0, 0, 0],
                         np.nan if silent else 80.0 + k, [k, 0.0, 80.0],
                         tendon_force_n=[np.nan if silent else 2.0, 1.0, 1.0, 1.0])
    recording, = load_recordings([path])
    np.testing.assert_allclose(recording.tendon_mm[:, 0], [0.0, 0.1, 0.2, 0.3, 0.4], rtol=0, atol=1e-12)
    np.testing.assert_allclose(recording.insertion_mm, [80.0, 81.0, 82.0, 83.0, 84.0], rtol=0, atol=1e-12)
    assert np.isnan(recording.tendon_force_n[[2, 3], 0]).all()   # a measurement, not an input: stays missing


def test_a_log_whose_axis_never_answered_is_refused(tmp_path):
    path = tmp_path / "never.csv"
    catheter = catheter_dict(flexible_length_mm=100.0, tendon_offset_mm=2.5, outer_diameter_mm=None)
    with LogWriter(path, catheter=catheter, sample_rate_hz=10.0, source="test") as writer:
        for k in range(5):
            writer.write(0.1 * k, [0, 0, 0, 0], 80.0, [0, 0, 0, 0], None, [k, 0.0, 80.0])
    with pytest.raises(LogFormatError, match="never.csv, column 'insertion_pos'.*never answered"):
        load_recordings([path])


def test_recording_with_a_missing_position_is_refused():
    t = np.arange(5.0)
    tendon = np.zeros((5, 4))
    tendon[3, 1] = np.nan
    with pytest.raises(RecordingError, match="tendon_mm is not finite at sample 3"):
        Recording("r", t, tendon, np.full(5, 80.0), np.zeros((5, 3)), None, 100.0, 2.5, None)
