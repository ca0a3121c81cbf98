"""Filling a log's empty position cells for model inputs: linear in time between an axis' nearest
measured rows, the nearest measured value at the edges, and a clear error when an axis has none."""
import math
from pathlib import Path

import numpy as np
import pytest

from crest.log import LogFormatError, LogWriter, catheter_dict, read_log
from crest.log.missing_positions import filled_positions_mm

NAN = math.nan


def _write(path: Path, t_s, tendon_pos_mm, insertion_pos_mm) -> Path:
    with LogWriter(path, catheter=catheter_dict(flexible_length_mm=80.0, tendon_offset_mm=2.5, outer_diameter_mm=6.0),
                   sample_rate_hz=100.0, source="unit test") as writer:
        for t, tendons, insertion in zip(t_s, tendon_pos_mm, insertion_pos_mm):
            writer.write(t, [0.0] * 4, 50.0, tendons, insertion)
    return path


def test_gaps_are_linear_in_time_between_the_axis_nearest_measured_rows(tmp_path: Path):
    t_s = [0.0, 0.1, 0.4, 1.0, 1.1]                  # uneven rows: the fill follows t, not the row index
    tendons = [[1.0, 0.0, 0.0, 0.0], [NAN, 0.0, 0.0, 0.0], [NAN, 0.0, 0.0, 0.0], [3.0, 0.0, 0.0, 0.0],
               [3.5, 0.0, 0.0, 0.0]]
    insertion = [50.0, 52.0, NAN, 58.0, 60.0]
    log = read_log(_write(tmp_path / "gaps.csv", t_s, tendons, insertion))
    tendon_mm, insertion_mm = filled_positions_mm(log)
    # tendon 1 between (0.0 s, 1 mm) and (1.0 s, 3 mm): 1 + 2 * t
    np.testing.assert_allclose(tendon_mm[:, 0], [1.0, 1.2, 1.8, 3.0, 3.5], rtol=0, atol=1e-12)
    # insertion between (0.1 s, 52 mm) and (1.0 s, 58 mm) at 0.4 s: 52 + 6 * 0.3 / 0.9
    np.testing.assert_allclose(insertion_mm, [50.0, 52.0, 54.0, 58.0, 60.0], rtol=0, atol=1e-12)
    assert tendon_mm[[0, 3, 4], 0].tolist() == [1.0, 3.0, 3.5]        # measured rows keep their value
    np.testing.assert_array_equal(tendon_mm[:, 1:], 0.0)               # other axes untouched
    assert np.isnan(log.tendon_pos_mm[1, 0]) and np.isnan(log.insertion_pos_mm[2])   # the log keeps its gaps


def test_before_the_first_and_after_the_last_measured_row_the_nearest_value_holds(tmp_path: Path):
    t_s = [0.0, 0.01, 0.02, 0.03, 0.04]
    tendons = [[NAN, 0, 0, 0], [NAN, 0, 0, 0], [2.0, 0, 0, 0], [2.5, 0, 0, 0], [NAN, 0, 0, 0]]
    insertion = [50.0, 50.0, 50.0, NAN, NAN]
    tendon_mm, insertion_mm = filled_positions_mm(read_log(_write(tmp_path / "edges.csv", t_s, tendons, insertion)))
    assert tendon_mm[:, 0].tolist() == [2.0, 2.0, 2.0, 2.5, 2.5]
    assert insertion_mm.tolist() == [50.0] * 5


def test_an_axis_with_no_measured_position_is_refused_naming_file_and_column(tmp_path: Path):
    path = _write(tmp_path / "never.csv", [0.0, 0.01], [[0, 0, NAN, 0], [0, 0, NAN, 0]], [50.0, 50.0])
    with pytest.raises(LogFormatError, match="never answered") as raised:
        filled_positions_mm(read_log(path))
    assert (raised.value.path, raised.value.column) == (path, "tendon_pos_3")
    assert str(raised.value).startswith(f"{path}, column 'tendon_pos_3'")


def test_a_log_without_gaps_gives_its_positions_unchanged(tmp_path: Path):
    tendons = [[1.0, 2.0, 3.0, 4.0], [1.5, 2.5, 3.5, 4.5]]
    log = read_log(_write(tmp_path / "full.csv", [0.0, 0.01], tendons, [50.0, 51.0]))
    tendon_mm, insertion_mm = filled_positions_mm(log)
    assert tendon_mm.tolist() == tendons and insertion_mm.tolist() == [50.0, 51.0]
