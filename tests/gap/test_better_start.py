"""Candidates start again from a better baseline (`model.gap.diagnosis.better_start`): when a base-only
fit (the plain refit, or a candidate with its effect switched off) fits the training log better than
the calibration did, the best candidates are fitted again from it, and each keeps the start from
which it fits the training log better. The result says which start each candidate kept."""
from model.gap.diagnosis import REFITS_FROM_BETTER_BASE
from tests.gap.conftest import diagnosed


def test_the_best_candidates_are_fitted_again_from_a_better_baseline_and_keep_the_better_start():
    result = diagnosed("torsion")
    # with torsion in the plant, a base-only fit beats the calibration made without it
    assert result["baseline"]["improved_by"] in ("the plain refit", "a candidate with its effect switched off")
    again = [c for c in result["candidates"] if c["train_rmse_mm_by_start"]]
    assert len(again) == REFITS_FROM_BETTER_BASE
    assert result["candidates"][0] in again, "the best candidate is among those fitted again"
    for candidate in again:
        by_start = candidate["train_rmse_mm_by_start"]
        assert set(by_start) == {"calibration", "better baseline"}
        assert candidate["started_from"] == min(by_start, key=by_start.get)
        assert candidate["train_rmse_mm"] <= by_start[candidate["started_from"]]
    assert all(c["started_from"] == "calibration" for c in result["candidates"] if c not in again)


def test_a_calibration_that_no_base_only_fit_beats_fits_every_candidate_once():
    result = diagnosed("sensor_offset")
    assert result["baseline"]["improved_by"] is None
    assert all(c["started_from"] == "calibration" and not c["train_rmse_mm_by_start"] for c in result["candidates"])
