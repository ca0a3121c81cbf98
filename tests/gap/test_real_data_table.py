"""`crest gap --real-data`: every real file held out once; clear refusals before any work."""
from pathlib import Path

from crest.gap.real_data_table import folds, table_markdown
from tests.cli.cli_runner import crest


def test_files_are_dealt_alternately_by_name_so_each_is_held_out_exactly_once():
    paths = [Path(name) for name in ("multi_sweep.csv", "average.csv", "max_sweep.csv", "preload_sweep.csv",
                                     "data.csv", "multi_sweep_backwards.csv")]
    first, second = folds(paths)
    assert [p.stem for p in first] == ["average", "max_sweep", "multi_sweep_backwards"]
    assert [p.stem for p in second] == ["data", "multi_sweep", "preload_sweep"]
    assert sorted(first + second) == sorted(paths)


def test_the_table_has_one_row_per_held_out_file_with_the_three_models_and_the_verdicts_grade():
    row = {"recording": "max_sweep", "fold": 1, "constant_curvature_mm": 10.234, "dahl_mm": 3.111,
           "dahl_verdict_mm": 3.0, "verdict": "tracker_offset", "confidence": "partial"}
    lines = table_markdown({"rows": [row, {**row, "verdict": "unexplained", "confidence": None}]}).splitlines()
    assert lines[-2] == "| max_sweep | 1 | 10.23 mm | 3.11 mm | 3.00 mm | tracker_offset (partial) |"
    assert lines[-1] == "| max_sweep | 1 | 10.23 mm | 3.11 mm | 3.00 mm | unexplained |"


def test_a_missing_data_folder_is_one_error_line_before_any_work(tmp_path):
    result = crest("gap", "--real-data", str(tmp_path / "absent"), "--json", str(tmp_path / "table.json"))
    assert result.returncode == 1 and "Traceback" not in result.stderr
    assert f"crest: error: no real data at {tmp_path / 'absent'}" in result.stderr
    assert not (tmp_path / "table.json").exists()


def test_logs_beside_real_data_are_refused(tmp_path):
    result = crest("gap", "train.csv", "--real-data")
    assert result.returncode == 1 and "--real-data makes its own folds" in result.stderr
