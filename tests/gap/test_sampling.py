"""The diagnosis says which rows of the logs it used (issue 17: no silent caps): a fit on a decimated
and capped log gives strict, finite JSON of the same shape as a fit on every row, with a "sampling"
block that names the decimation, the cap and the rows the fits and the held-out error used."""
import functools
import json
import tempfile
from pathlib import Path

from crest.gap.log_diagnosis import diagnose_logs
from crest.reports.gap_report import markdown, sampling_lines
from model.gap.diagnosis import DiagnosisSettings
from model.gap.simulation import Resolution
from tests.gap.conftest import SAMPLE_RATE_HZ, record_case

FIT_CAP_ROWS = 150


def small_settings(resolution: Resolution) -> DiagnosisSettings:
    """A short diagnosis (one candidate, few iterations): the JSON's shape, not the verdict, is under test."""
    return DiagnosisSettings(resolution=resolution, workers=1, baseline_iterations=2, candidate_iterations=2,
                             pair_candidates=0, effects=("tracker_offset",))


@functools.cache
def diagnoses() -> tuple[dict, dict]:
    """(every row, decimated 4x and capped) diagnoses of the same 20 Hz logs, as strict JSON."""
    every_row = Resolution(n_elements=6, fit_rate_hz=SAMPLE_RATE_HZ, max_fit_samples=10 ** 6)
    decimated = Resolution(n_elements=6, fit_rate_hz=SAMPLE_RATE_HZ / 4, max_fit_samples=FIT_CAP_ROWS)
    with tempfile.TemporaryDirectory() as folder:
        train, holdout = record_case(Path(folder), {"tracker_offset": (1.0, -0.5, 0.5)})
        return tuple(json.loads(json.dumps(diagnose_logs([train], [holdout], settings=small_settings(r)),
                                           allow_nan=False)) for r in (every_row, decimated))


def shape(tree, path: str = "") -> set[str]:
    """The key paths of a JSON tree down to its lists (a list's length and items depend on the data)."""
    if isinstance(tree, dict):
        return {path} | set().union(*(shape(value, f"{path}/{key}") for key, value in tree.items()))
    return {f"{path}[]" if isinstance(tree, list) else path}


def test_a_decimated_and_capped_fit_says_so_in_finite_json_of_the_same_shape():
    full, decimated = diagnoses()
    assert decimated["non_finite"] == [] and full["non_finite"] == []
    assert shape(decimated) == shape(full)
    assert [shape(row) for row in decimated["sampling"]["train"]] == [shape(row) for row in full["sampling"]["train"]]
    sampling = decimated["sampling"]
    assert sampling["decimated"] and sampling["capped"]
    assert sampling["max_fit_samples"] == FIT_CAP_ROWS and sampling["fit_rate_hz"] == SAMPLE_RATE_HZ / 4
    (train,), (held,) = sampling["train"], sampling["holdout"]
    assert train["decimation"] == held["decimation"] == 4
    assert sampling["train_rows_used"] == train["rows_used"] <= FIT_CAP_ROWS
    assert train["duration_used_s"] < train["duration_s"]          # the fits saw the head of the log only
    assert held["rows_used"] == -(-held["rows"] // 4)              # decimated, never cut
    assert held["duration_used_s"] > held["duration_s"] - 4 / SAMPLE_RATE_HZ
    # the held-out error is taken on the rows the block names: one per decimated row with a tip
    time_bins = [row for row in decimated["where"] if row["group"] == "time"]
    assert sum(row["samples"] for row in time_bins) == held["rows_used_with_tip"]
    assert decimated["baseline"]["noise_mm"] is not None


def test_a_fit_on_every_row_says_it_used_every_row():
    sampling = diagnoses()[0]["sampling"]
    assert not sampling["decimated"] and not sampling["capped"]
    assert sampling["train_rows_used"] == sampling["train_rows"]
    assert sampling["holdout_rows_used"] == sampling["holdout_rows"]


def test_the_report_and_the_verdict_lines_name_the_cap_and_the_decimation():
    full, decimated = diagnoses()
    fit_line, held_line = sampling_lines(decimated["sampling"])
    assert f"cut to {FIT_CAP_ROWS} rows" in fit_line and "one in 4" in fit_line and "the first" in fit_line
    assert "one in 4" in held_line and "the first" not in held_line
    assert fit_line in markdown(decimated)
    assert not any("one in" in line or "cut to" in line for line in sampling_lines(full["sampling"]))
