"""The continuum_nathan importer: real data into crest logs (skipped without the data) and clear
errors on malformed source files (always run, on synthetic files)."""

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from crest.importers.continuum_nathan import (
    DataImportError,
    DataImportWarning,
    import_all,
    import_file,
)
from crest.log import read_log

DATA_DIR = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "continuum_nathan"
needs_data = pytest.mark.skipif(not DATA_DIR.is_dir(), reason=f"real data absent ({DATA_DIR})")
CIRCLES = "experiments/sweep/output/data_2024_05_21_14_57_12.dat"
AVERAGE = "experiments/model_comparison/test_data/average_2024_05_12_18_47_41.dat"


@pytest.fixture(scope="module")
def imported(tmp_path_factory: pytest.TempPathFactory) -> dict:
    if not DATA_DIR.is_dir():
        pytest.skip(f"real data absent ({DATA_DIR})")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        paths = import_all(DATA_DIR, tmp_path_factory.mktemp("continuum_nathan"))
    return {"logs": {path.stem: read_log(path) for path in paths},
            "warnings": [str(w.message) for w in caught if issubclass(w.category, DataImportWarning)]}


@needs_data
def test_expanding_circles_keep_512_poses_and_reject_row_335(imported):
    log = imported["logs"]["data_2024_05_21_14_57_12"]
    assert len(log) == 512
    assert list(np.flatnonzero(~log.tip_valid)) == [335]
    assert log.sidecar["summary"]["import"]["rejected_tip_index"] == [335]
    assert "source index: 335" in log.notes
    assert any("data_2024_05_21_14_57_12.dat" in text and "[335]" in text for text in imported["warnings"])
    assert np.array_equal(log.t_s, np.arange(512) * 1.0) and log.sample_rate_hz == 1.0
    # Row n: ring k = n // 32, A = 0.75 (k+1), phi = 2 pi (n % 32) / 32; dl = -A [cos, sin, -cos, -sin]; tendon = -dl.
    n = np.arange(512)
    amplitude = 0.75 * (n // 32 + 1)
    phi = 2 * np.pi * (n % 32) / 32
    expected = amplitude[:, None] * np.stack([np.cos(phi), np.sin(phi), -np.cos(phi), -np.sin(phi)], axis=1)
    np.testing.assert_allclose(log.tendon_cmd_mm, expected, atol=1e-12)
    np.testing.assert_array_equal(log.tendon_pos_mm, log.tendon_cmd_mm)
    assert np.all(log.insertion_cmd_mm == 64.0) and np.all(log.insertion_pos_mm == 64.0)


@needs_data
def test_tip_near_zero_displacement_is_about_64_mm_up_the_backbone(imported):
    circles = imported["logs"]["data_2024_05_21_14_57_12"]
    first_ring = circles.tip_mm[:32]  # 0.75 mm of cable: nearly straight
    assert 63.0 < np.mean(first_ring[:, 2]) < 65.0
    # Nearly straight: within 8 mm of the z axis (less than 15 deg of bend over 64 mm, registration offset included).
    assert np.all(np.hypot(first_ring[:, 0], first_ring[:, 1]) < 8.0)
    average = imported["logs"]["average_2024_05_12_18_47_41"]
    smallest = average.tip_mm[::12]  # A = pi/6 mm in each of the 24 directions
    assert 63.0 < np.mean(smallest[:, 2]) < 65.0


@needs_data
def test_pulling_a_tendon_bends_the_tip_toward_it(imported):
    """Tendon k sits at (k-1)*90 deg; pulling it (positive crest value) moves the tip that way."""
    sweep = imported["logs"]["max_sweep"]
    for column, pulled, direction in [(0, 0, (1, 0)), (32, 1, (0, 1)), (64, 2, (-1, 0)), (96, 3, (0, -1))]:
        assert sweep.tendon_cmd_mm[column, pulled] == pytest.approx(12.0)
        tip_xy = sweep.tip_mm[column, :2]
        assert np.dot(tip_xy, direction) > 25.0, (column, tip_xy)
    backwards = imported["logs"]["multi_sweep_backwards"]
    assert backwards.tendon_cmd_mm[32, 3] == pytest.approx(12.0)  # clockwise: a quarter turn reaches -y
    assert backwards.tip_mm[32, 1] < -25.0


@needs_data
def test_average_grid_drops_the_placeholder_row(imported):
    log = imported["logs"]["average_2024_05_12_18_47_41"]
    assert len(log) == 288 and log.t_s[0] == 1.0
    assert np.all(log.tip_valid)
    assert log.sidecar["summary"]["import"]["dropped_index"] == [0]
    # Row 1 + 12 a + (j - 1): dl1 = A cos(alpha), A = j pi/6, alpha = 2 pi a / 24; tendon1 = -dl1.
    assert log.tendon_cmd_mm[0, 0] == pytest.approx(-math.pi / 6)
    assert log.tendon_cmd_mm[11, 0] == pytest.approx(-12 * math.pi / 6)


@needs_data
def test_every_known_file_imports_with_its_geometry_and_provenance(imported):
    lengths = {name: len(log) for name, log in imported["logs"].items()}
    assert lengths == {"data_2024_05_21_14_57_12": 512, "average_2024_05_12_18_47_41": 288, "max_sweep": 128,
                       "multi_sweep": 1024, "multi_sweep_backwards": 1024, "preload_sweep": 128}
    for log in imported["logs"].values():
        assert log.catheter == {"flexible_length_mm": 64.0, "outer_diameter_mm": None, "tendon_offset_mm": 7.5,
                                "tendon_angles_deg": [0.0, 90.0, 180.0, 270.0]}
        assert log.source.startswith("nathanmcallister/continuum_nathan@")
        assert "calibrate" in log.notes and "t = source index * 1.0 s" in log.notes


HEADER = "DATE: 2024-5-21\nTIME: 14-57-12\nNUM_CABLES: 4\nNUM_AURORAS: 1\nNUM_MEASUREMENTS: {count}\n---\n"
ROW = "{idx},-0.75,-0.0,0.75,0.0,{x},-2.1,63.5,0.06,0.06,0.03\n"


def _format_a(tmp_path: Path, rows: list[str], count: int | None = None, header: str = HEADER) -> Path:
    path = tmp_path / "synthetic.dat"
    path.write_text(header.format(count=len(rows) if count is None else count) + "".join(rows))
    return path


def test_synthetic_format_a_with_non_finite_and_absurd_tips(tmp_path: Path):
    rows = [ROW.format(idx=i, x=x) for i, x in enumerate(["0.05", "nan", "1.5e24", "-inf", "0.1"])]
    with pytest.warns(DataImportWarning, match=r"\[1, 2, 3\]"):
        out = import_file(_format_a(tmp_path, rows), tmp_path / "out.csv")
    log = read_log(out)
    assert log.tip_valid.tolist() == [True, False, False, False, True]
    assert log.tendon_cmd_mm[0].tolist() == [0.75, 0.0, -0.75, 0.0]
    assert not np.signbit(log.tendon_cmd_mm[0, 1])  # -(-0.0) is written as 0.0


@pytest.mark.parametrize(("header", "rows", "count", "line", "problem"), [
    (HEADER.replace("NUM_CABLES: 4", "NUM_CABLES: 6"), 2, None, 3, "NUM_CABLES must be 4"),
    (HEADER.replace("NUM_AURORAS: 1", "num_coils: 2"), 2, None, 4, "NUM_AURORAS must be 1"),
    (HEADER.replace("TIME:", "TIME"), 2, None, 2, "expected header line 'TIME: ...'"),
    (HEADER.replace("---", "==="), 2, None, 6, "header end '---'"),
    (HEADER, 2, 3, 5, "NUM_MEASUREMENTS says 3 rows, the file has 2"),
    (HEADER, 2, "x", 5, "NUM_MEASUREMENTS must be a whole number"),
])
def test_malformed_format_a_header_names_the_line(tmp_path: Path, header, rows, count, line, problem):
    path = _format_a(tmp_path, [ROW.format(idx=i, x=0.1) for i in range(rows)], count, header)
    with pytest.raises(DataImportError) as raised:
        import_file(path, tmp_path / "out.csv")
    assert raised.value.line == line
    assert str(raised.value).startswith(f"{path}, line {line}: ") and problem in str(raised.value)
    assert not (tmp_path / "out.csv").exists()


@pytest.mark.parametrize(("bad_row", "problem"), [
    ("1,-0.75,0.0,0.75,0.0,0.1,-2.1,63.5,0.06,0.06\n", "expected 11 values"),
    ("1,-0.75,zero,0.75,0.0,0.1,-2.1,63.5,0.06,0.06,0.03\n", "dl2: not a number: 'zero'"),
    ("1,-0.75,nan,0.75,0.0,0.1,-2.1,63.5,0.06,0.06,0.03\n", "dl1..dl4 must be finite commands"),
    ("7,-0.75,0.0,0.75,0.0,0.1,-2.1,63.5,0.06,0.06,0.03\n", "idx is '7', expected 1"),
])
def test_malformed_format_a_row_names_the_line(tmp_path: Path, bad_row: str, problem: str):
    path = _format_a(tmp_path, [ROW.format(idx=0, x=0.1), bad_row, ROW.format(idx=2, x=0.1)])
    with pytest.raises(DataImportError, match=r"synthetic\.dat, line 8: ") as raised:
        import_file(path, tmp_path / "out.csv")
    assert problem in str(raised.value)


def test_format_b_errors_name_file_and_line(tmp_path: Path):
    unknown = tmp_path / "my_sweep.dat"
    unknown.write_text("1.0,2.0\n3.0,4.0\n5.0,6.0\n")
    with pytest.raises(DataImportError, match="my_sweep.dat: neither format A .* only max_sweep.dat"):
        import_file(unknown, tmp_path / "out.csv")
    ragged = tmp_path / "max_sweep.dat"
    row = ",".join(["1.0"] * 128)
    ragged.write_text(f"{row}\n{row},2.0\n{row}\n")
    with pytest.raises(DataImportError, match=r"max_sweep\.dat, line 2: row has 129 columns"):
        import_file(ragged, tmp_path / "out.csv")
    ragged.write_text(f"{row}\n{row}\n")
    with pytest.raises(DataImportError, match=r"max_sweep\.dat, line 3: format B has 3 rows"):
        import_file(ragged, tmp_path / "out.csv")
    ragged.write_text(f"{row}\n{row.replace('1.0', 'x', 1)}\n{row}\n")
    with pytest.raises(DataImportError, match=r"max_sweep\.dat, line 2: y, column 0: not a number"):
        import_file(ragged, tmp_path / "out.csv")


def test_missing_source_is_a_data_import_error(tmp_path: Path):
    with pytest.raises(DataImportError, match="absent.dat: cannot read the file"):
        import_file(tmp_path / "absent.dat", tmp_path / "out.csv")
