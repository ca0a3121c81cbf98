"""Writer and reader of crest-log/1: what is written is read back exactly, with its sidecar."""

import json
import math
from pathlib import Path

import numpy as np
import pytest

from crest.log import FORMAT_TAG, LogWriter, catheter_dict, read_log

CATHETER = catheter_dict(flexible_length_mm=80.0, tendon_offset_mm=2.5, outer_diameter_mm=6.0)


def _open(path: Path, **options) -> LogWriter:
    return LogWriter(path, catheter=CATHETER, sample_rate_hz=100.0, source="unit test", **options)


def test_round_trip_is_exact_with_missing_tip_samples(tmp_path: Path):
    rng = np.random.default_rng(7)
    count = 200
    t_s = np.cumsum(rng.uniform(0.001, 0.02, count))
    tendon_cmd = rng.normal(0, 5, (count, 4))
    tendon_pos = tendon_cmd + rng.normal(0, 0.01, (count, 4))
    insertion = rng.uniform(20, 100, count)
    tip = rng.normal(0, 30, (count, 3))
    tip[[3, 50, 199]] = np.nan
    force = rng.uniform(0, 40, (count, 4))
    tip_ref = rng.normal(0, 30, (count, 3))
    path = tmp_path / "run.csv"
    with _open(path, tendon_force=True, tip_ref=True, notes="round trip",
               config={"sync": {"period_s": 0.01}}) as writer:
        for row in range(count):
            writer.write(t_s[row], tendon_cmd[row], insertion[row], tendon_pos[row], insertion[row] + 0.1,
                         None if row == 3 else tip[row], tendon_force_n=force[row], tip_ref_mm=tip_ref[row])
        writer.close({"stop_cause": "completed"})

    log = read_log(path)
    assert len(log) == count
    np.testing.assert_array_equal(log.t_s, t_s)
    np.testing.assert_array_equal(log.tendon_cmd_mm, tendon_cmd)
    np.testing.assert_array_equal(log.tendon_pos_mm, tendon_pos)
    np.testing.assert_array_equal(log.insertion_cmd_mm, insertion)
    np.testing.assert_array_equal(log.insertion_pos_mm, insertion + 0.1)
    np.testing.assert_array_equal(log.tip_mm, tip)  # NaN rows compare equal to NaN
    np.testing.assert_array_equal(log.tendon_force_n, force)
    np.testing.assert_array_equal(log.tip_ref_mm, tip_ref)
    assert list(np.flatnonzero(~log.tip_valid)) == [3, 50, 199]
    assert log.catheter == CATHETER and log.sample_rate_hz == 100.0
    assert (log.source, log.notes) == ("unit test", "round trip")
    assert log.sidecar["config"] == {"sync": {"period_s": 0.01}}
    assert log.sidecar["summary"]["stop_cause"] == "completed"
    assert log.sidecar["summary"]["samples"] == count
    assert log.sidecar["summary"]["duration_s"] == pytest.approx(t_s[-1] - t_s[0])
    assert log.sidecar["software"]["crest_version"]
    with pytest.raises(ValueError):
        log.tip_mm[0, 0] = 1.0  # the arrays are read-only


def test_optional_columns_are_absent_when_not_recorded(tmp_path: Path):
    path = tmp_path / "plain.csv"
    with _open(path) as writer:
        writer.write(0.0, [1, 0, -1, 0], 50, [1, 0, -1, 0], 50, [0, 0, 50])
    log = read_log(path)
    assert log.tendon_force_n is None and log.tip_ref_mm is None
    assert path.read_text().splitlines()[0] == ("t,tendon_cmd_1,tendon_cmd_2,tendon_cmd_3,tendon_cmd_4,insertion_cmd,"
                                                "tendon_pos_1,tendon_pos_2,tendon_pos_3,tendon_pos_4,insertion_pos,"
                                                "tip_x,tip_y,tip_z")


def test_sidecar_is_written_at_open_and_summarised_at_close(tmp_path: Path):
    path = tmp_path / "open.csv"
    writer = _open(path)
    sidecar = json.loads(path.with_suffix(".json").read_text())
    assert sidecar["format"] == FORMAT_TAG and "summary" not in sidecar
    assert path.read_text().count("\n") == 1  # the header is on disk before the first sample
    with pytest.raises(RuntimeError):
        with writer:
            writer.write(0.0, [0] * 4, 50, [0] * 4, 50)
            raise RuntimeError("tension limit on tendon2")
    summary = json.loads(path.with_suffix(".json").read_text())["summary"]
    assert summary["stop_cause"] == "RuntimeError: tension limit on tendon2"
    assert summary["samples"] == 1


def test_a_stop_after_close_is_added_to_the_summary(tmp_path: Path):
    path = tmp_path / "ended.csv"
    writer = _open(path)
    with pytest.raises(ValueError, match="still open"):
        writer.amend_summary({"stop_cause": "too early"})
    writer.write(0.0, [0] * 4, 50, [0] * 4, 50)
    writer.close({"rms_tip_error_mm": 0.3})
    writer.amend_summary({"stop_cause": "SDO failure while closing", "exit_code": 14})
    summary = json.loads(path.with_suffix(".json").read_text())["summary"]
    assert summary["samples"] == 1 and summary["rms_tip_error_mm"] == 0.3
    assert (summary["stop_cause"], summary["exit_code"]) == ("SDO failure while closing", 14)
    assert len(read_log(path)) == 1


def test_writer_refuses_what_the_reader_would_reject(tmp_path: Path):
    with _open(tmp_path / "bad.csv") as writer:
        with pytest.raises(ValueError, match="tendon_cmd_3 must be a finite number"):
            writer.write(0.0, [0, 0, math.nan, 0], 50, [0] * 4, 50)
        with pytest.raises(ValueError, match="tip_y must be finite, or all of tip_x, tip_y, tip_z missing"):
            writer.write(0.0, [0] * 4, 50, [0] * 4, 50, [1.0, math.nan, 2.0])
        writer.write(1.0, [0] * 4, 50, [0] * 4, 50)
        with pytest.raises(ValueError, match="t must increase strictly"):
            writer.write(1.0, [0] * 4, 50, [0] * 4, 50)
    assert len(read_log(tmp_path / "bad.csv")) == 1
    with pytest.raises(FileExistsError, match="overwrite=True"):
        _open(tmp_path / "bad.csv")


def test_unwritten_rows_never_span_more_than_the_flush_interval(tmp_path: Path):
    """With a stopped wall clock, log time alone forces a flush: the durable file lags < 0.5 s."""
    path = tmp_path / "durable.csv"
    with _open(path, clock=lambda: 0.0) as writer:
        for row in range(300):
            t_s = row * 0.01
            writer.write(t_s, [0] * 4, 50, [0] * 4, 50)
            rows_on_disk = len(path.read_text().splitlines()) - 1
            first_missing_t_s = rows_on_disk * 0.01
            assert t_s - first_missing_t_s < 0.5
        assert len(path.read_text().splitlines()) < 301  # the last rows wait for the next flush ...
    assert len(read_log(path)) == 300  # ... and close writes them


def test_a_position_the_drive_did_not_answer_is_an_empty_cell_read_back_as_nan(tmp_path: Path):
    path = tmp_path / "silent.csv"
    with _open(path, tendon_force=True) as writer:
        writer.write(0.0, [1, 0, -1, 0], 50, [1.0, 0.5, -1.0, 0.0], 50.0, tendon_force_n=[2, 3, 4, 5])
        writer.write(0.01, [1, 0, -1, 0], 50, [1.0, math.nan, -1.0, 0.0], None, tendon_force_n=[2, math.nan, 4, 5])
        writer.write(0.02, [1, 0, -1, 0], 50, [None, 0.5, -1.0, 0.0], 50.1, tendon_force_n=[None, 3, 4, 5])
    assert path.read_text().splitlines()[2].split(",")[6:11] == ["1.0", "", "-1.0", "0.0", ""]
    log = read_log(path)
    np.testing.assert_array_equal(log.tendon_pos_mm, [[1.0, 0.5, -1.0, 0.0], [1.0, np.nan, -1.0, 0.0],
                                                      [np.nan, 0.5, -1.0, 0.0]])
    np.testing.assert_array_equal(log.insertion_pos_mm, [50.0, np.nan, 50.1])
    np.testing.assert_array_equal(log.tendon_force_n, [[2, 3, 4, 5], [2, np.nan, 4, 5], [np.nan, 3, 4, 5]])
    np.testing.assert_array_equal(log.tendon_cmd_mm, [[1, 0, -1, 0]] * 3)   # commands stay numbers


def test_writer_refuses_infinite_positions_and_a_force_without_its_position(tmp_path: Path):
    with _open(tmp_path / "bad.csv", tendon_force=True) as writer:
        with pytest.raises(ValueError, match="tendon_pos_2 must be a finite number, or NaN/None when not measured"):
            writer.write(0.0, [0] * 4, 50, [0, math.inf, 0, 0], 50, tendon_force_n=[1] * 4)
        with pytest.raises(ValueError, match="insertion_pos must be a finite number, or NaN/None"):
            writer.write(0.0, [0] * 4, 50, [0] * 4, -math.inf, tendon_force_n=[1] * 4)
        with pytest.raises(ValueError, match="tendon_pos_3 is missing .* but tendon_force_3 is 1.0"):
            writer.write(0.0, [0] * 4, 50, [0, 0, math.nan, 0], 50, tendon_force_n=[1] * 4)
        with pytest.raises(ValueError, match="insertion_cmd must be a finite number"):
            writer.write(0.0, [0] * 4, math.nan, [0] * 4, 50, tendon_force_n=[1] * 4)
        with pytest.raises(ValueError, match="t must be finite"):
            writer.write(math.nan, [0] * 4, 50, [0] * 4, 50, tendon_force_n=[1] * 4)
    assert len(read_log(tmp_path / "bad.csv")) == 0
