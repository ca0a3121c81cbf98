"""Counting a run's rows with a tip, and when the tracker was lost (no tip for longer than the
loss timeout; the loss time is the last tip's)."""
import pytest

from crest.experiment.tip_coverage import TipCoverage

ROW_S = 0.01
LOSS_TIMEOUT_S = 0.25


def _rows(coverage: TipCoverage, has_tip, start_s: float = 0.0) -> None:
    for row, tip in enumerate(has_tip):
        coverage.add(start_s + row * ROW_S, tip)


def test_gaps_between_frames_and_short_dropouts_are_not_a_loss():
    coverage = TipCoverage(LOSS_TIMEOUT_S)
    frames = [row % 5 in (0, 2) for row in range(200)]            # 40 Hz frames at a 100 Hz SYNC
    frames[50:70] = [False] * 20                                  # 0.2 s without a tip: dropout
    _rows(coverage, frames, start_s=12.0)
    assert coverage.lost_at_s is None and coverage.loss_sentence() is None
    assert coverage.summary() == {"rows_with_tip": sum(frames), "rows_without_tip": 200 - sum(frames),
                                  "tracker_lost_at_s": None, "rows_after_tracker_loss": None,
                                  "rows_with_tip_after_tracker_loss": None}


def test_a_loss_is_dated_at_the_last_tip_and_tips_after_it_are_counted():
    coverage = TipCoverage(LOSS_TIMEOUT_S)
    frames = [row % 5 in (0, 2) for row in range(300)]
    frames[101:250] = [False] * 149                               # last tip at row 100, back at row 250
    _rows(coverage, frames, start_s=12.0)
    assert coverage.lost_at_s == pytest.approx(100 * ROW_S)       # in s since the first row
    back = sum(frames[250:])
    summary = coverage.summary()
    assert summary["rows_after_tracker_loss"] == 199 and summary["rows_with_tip_after_tracker_loss"] == back
    assert coverage.loss_sentence() == f"tracker lost at 1.00 s; {back} of 199 rows after it have a tip"


def test_no_tip_from_the_start_is_a_loss_at_the_first_row():
    coverage = TipCoverage(LOSS_TIMEOUT_S)
    _rows(coverage, [False] * 100)
    assert coverage.lost_at_s == 0.0
    assert coverage.summary()["rows_after_tracker_loss"] == 99


def test_without_a_tracker_nothing_is_lost():
    coverage = TipCoverage(None)
    _rows(coverage, [False] * 100)
    assert coverage.lost_at_s is None and coverage.summary()["rows_without_tip"] == 100
