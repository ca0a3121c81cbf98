"""The log reader refuses malformed logs with an error naming file, line and column."""

import json
import math
from pathlib import Path

import pytest

from crest.log import LogFormatError, TruncatedLogWarning, catheter_dict, read_log

HEADER = ("t,tendon_cmd_1,tendon_cmd_2,tendon_cmd_3,tendon_cmd_4,insertion_cmd,"
          "tendon_pos_1,tendon_pos_2,tendon_pos_3,tendon_pos_4,insertion_pos,tip_x,tip_y,tip_z")
ROW_0 = "0.0,1,0,-1,0,50,1,0,-1,0,50,0.5,0,49.9"
ROW_1 = "0.01,1.5,0,-1.5,0,50,1.4,0,-1.4,0,50,0.8,0,49.8"
FORCES = "tendon_force_1,tendon_force_2,tendon_force_3,tendon_force_4"
SIDECAR = {"format": "crest-log/1",
           "catheter": catheter_dict(flexible_length_mm=80, tendon_offset_mm=2.5, outer_diameter_mm=6),
           "sample_rate_hz": 100.0, "source": "hand written", "notes": ""}


def _log(tmp_path: Path, body: str, sidecar: dict | None = SIDECAR) -> Path:
    path = tmp_path / "log.csv"
    path.write_text(body)
    if sidecar is not None:
        path.with_suffix(".json").write_text(json.dumps(sidecar))
    return path


def test_hand_written_log_with_crlf_and_any_column_order_is_read(tmp_path: Path):
    columns = HEADER.split(",")
    order = list(reversed(range(len(columns))))
    lines = [HEADER, ROW_0, ROW_1]
    body = "".join(",".join(line.split(",")[i] for i in order) + "\r\n" for line in lines)
    log = read_log(_log(tmp_path, body))
    assert log.tendon_cmd_mm.tolist() == [[1, 0, -1, 0], [1.5, 0, -1.5, 0]]
    assert log.tip_mm[1].tolist() == [0.8, 0, 49.8]


BAD_BODIES = [
    (f"{HEADER}\n{ROW_0}\n0.01,1,0,-1,0,50,1,0,x1,0,50,0,0,50\n", 3, "tendon_pos_3", "not a finite number"),
    (f"{HEADER}\n{ROW_0}\n0.01,1,0,-1,0,50,1,0,nan,0,50,0,0,50\n", 3, "tendon_pos_3", "empty cell"),
    (f"{HEADER}\n{ROW_0}\n0.01,1,0,-1,0,50,1,0,-1,0,50,inf,0,50\n", 3, "tip_x", "not a finite number"),
    (f"{HEADER}\n{ROW_0}\n0.01,1,0,-1,0,50,1,0,-1,0,50,1e999,0,50\n", 3, "tip_x", "not a finite number"),
    (f"{HEADER}\n{ROW_0}\n0.01,1,,-1,0,50,1,0,-1,0,50,0,0,50\n", 3, "tendon_cmd_2", "must hold a number"),
    (f"{HEADER}\n{ROW_0}\n0.01,1,0,-1,0,,1,0,-1,0,50,0,0,50\n", 3, "insertion_cmd", "must hold a number"),
    (f"{HEADER}\n{ROW_0}\n,1,0,-1,0,50,1,0,-1,0,50,0,0,50\n", 3, "t", "must hold a number"),
    (f"{HEADER}\n{ROW_0}\n0.01,1,0,-1,0,50,1,0,-1,0,inf,0,0,50\n", 3, "insertion_pos", "not a finite number"),
    (f"{HEADER},{FORCES}\n{ROW_0},1,2,3,4\n0.01,1,0,-1,0,50,1,,-1,0,50,0,0,50,1,2,3,4\n", 3, "tendon_force_2",
     "tendon_pos_2 is empty"),
    (f"{HEADER}\n{ROW_0}\n0.01,1,0,-1,0,50,1,0,-1,0,50,,0,50\n", 3, "tip_x", "all present or all empty"),
    (f"{HEADER}\n{ROW_1}\n{ROW_0}\n", 3, "t", "increase strictly"),
    (f"{HEADER}\n{ROW_0}\n{ROW_0}\n", 3, "t", "increase strictly"),
    (f"{HEADER}\n{ROW_0}\n0.01,1,0\n", 3, None, "expected 14 cells, got 3"),
    (f"{HEADER}\n{ROW_0}\n\n{ROW_1}\n", 3, None, "expected 14 cells, got 1"),
    (f"{HEADER.replace(',tip_z', '')}\n", 1, None, "missing required column(s) tip_z"),
    (f"{HEADER},tip_x\n", 1, "tip_x", "twice"),
    (f"{HEADER},tip_temperature\n", 1, "tip_temperature", "unknown column"),
    (f"{HEADER},tendon_force_1,tendon_force_2\n", 1, None, "needs all of tendon_force_1"),
    (f"{HEADER}\n{ROW_0}\n0.01,1,0,-1,0,50,1,0,-1,0,50,0,0,5\xe90\n", 3, None, "non-ASCII"),
    ("", 1, None, "empty file"),
    (HEADER, 1, None, "header line is incomplete"),
]


@pytest.mark.parametrize(("body", "line", "column", "problem"), BAD_BODIES)
def test_malformed_body_names_line_and_column(tmp_path: Path, body: str, line: int, column: str | None, problem: str):
    path = _log(tmp_path, body)
    with pytest.raises(LogFormatError) as raised:
        read_log(path)
    error = raised.value
    assert (error.path, error.line, error.column) == (path, line, column)
    assert problem in str(error)
    assert str(error).startswith(f"{path}, line {line}")


@pytest.mark.parametrize(("change", "problem"), [
    ({"format": "crest-log/2"}, "expected 'crest-log/1'"),
    ({"format": None}, "expected 'crest-log/1'"),
    ({"sample_rate_hz": 0}, "sample_rate_hz must be a finite number > 0"),
    ({"sample_rate_hz": "100"}, "sample_rate_hz must be a finite number > 0"),
    ({"catheter": {"flexible_length_mm": 80, "tendon_offset_mm": 2.5, "tendon_angles_deg": [0, 90, 180, 270]}},
     "outer_diameter_mm is missing"),
    ({"catheter": {**SIDECAR["catheter"], "tendon_angles_deg": [0, 90, 180]}}, "tendon_angles_deg"),
    ({"catheter": {**SIDECAR["catheter"], "tendon_offset_mm": -1}}, "tendon_offset_mm"),
    ({"notes": None}, "'notes' must be a JSON string"),
    ({"plant": {"family": "rod"}}, "'plant' must be a JSON string"),
])
def test_bad_sidecar_is_named(tmp_path: Path, change: dict, problem: str):
    path = _log(tmp_path, f"{HEADER}\n{ROW_0}\n", {**SIDECAR, **change})
    with pytest.raises(LogFormatError, match="log.json: ") as raised:
        read_log(path)
    assert problem in str(raised.value)


def test_missing_or_invalid_sidecar(tmp_path: Path):
    path = _log(tmp_path, f"{HEADER}\n{ROW_0}\n", sidecar=None)
    with pytest.raises(LogFormatError, match=r"log\.json: the sidecar of log\.csv is missing"):
        read_log(path)
    path.with_suffix(".json").write_text('{"format": "crest-log/1",\n "sample_rate_hz": NaN}')
    with pytest.raises(LogFormatError, match=r"log\.json: invalid JSON: NaN is not valid JSON"):
        read_log(path)
    path.with_suffix(".json").write_text('{"format": "crest-log/1",\n "source": }')
    with pytest.raises(LogFormatError, match=r"log\.json, line 2: invalid JSON"):
        read_log(path)


def test_partial_last_line_of_a_killed_writer_is_dropped_with_a_warning(tmp_path: Path):
    path = _log(tmp_path, f"{HEADER}\n{ROW_0}\n{ROW_1[:-3]}")
    with pytest.warns(TruncatedLogWarning, match="line 3"):
        log = read_log(path)
    assert log.t_s.tolist() == [0.0]


def test_header_only_log_is_an_empty_log(tmp_path: Path):
    log = read_log(_log(tmp_path, f"{HEADER}\n"))
    assert len(log) == 0 and log.tendon_cmd_mm.shape == (0, 4) and log.tip_mm.shape == (0, 3)


def test_empty_position_cells_are_positions_not_measured(tmp_path: Path):
    """An empty tendon_pos_k / insertion_pos is a drive that did not answer: NaN, with its force empty."""
    body = (f"{HEADER},{FORCES}\n{ROW_0},1,2,3,4\n"
            "0.01,1,0,-1,0,50,1,,-1,0,,0,0,50,1,,3,4\n"
            "0.02,1,0,-1,0,50,,0,-1,0,50,,,,,2,3,\n")
    log = read_log(_log(tmp_path, body))
    assert log.tendon_pos_mm[1].tolist()[::2] == [1, -1] and math.isnan(log.tendon_pos_mm[1, 1])
    assert math.isnan(log.insertion_pos_mm[1]) and log.insertion_pos_mm[2] == 50
    assert math.isnan(log.tendon_pos_mm[2, 0]) and math.isnan(log.tendon_force_n[2, 0])
    assert math.isnan(log.tendon_force_n[2, 3]) and log.tendon_pos_mm[2, 3] == 0   # a force may be missing alone
    assert log.tendon_cmd_mm.tolist() == [[1, 0, -1, 0]] * 3
