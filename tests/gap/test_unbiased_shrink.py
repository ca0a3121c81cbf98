"""Unbiased shrink (issue 14, item 5): the effect is chosen on one half of the held-out samples and its
shrink is reported on the other, so the luck that won the choice is not published."""
import numpy as np

from model.gap.calibration import rmse_mm
from model.gap.holdout_split import SEGMENTS_PER_RECORDING, split_holdout


def test_halves_alternate_in_time_blocks_and_cover_every_sample_once():
    split = split_holdout([160, 45])
    first = split.selection[0]
    assert len(first) == 160 and first.sum() == 80
    blocks = first.reshape(SEGMENTS_PER_RECORDING, -1)       # 10 samples per block
    assert all(block.all() or not block.any() for block in blocks)
    assert [bool(block[0]) for block in blocks] == [k % 2 == 0 for k in range(SEGMENTS_PER_RECORDING)]
    errors = [np.ones((160, 3)), np.ones((45, 3))]
    assert sum(map(len, split.selected(errors))) + sum(map(len, split.reported(errors))) == 205
    assert split.as_dict()["selection_samples"] + split.as_dict()["report_samples"] == 205


def test_best_of_nine_noise_fits_looks_better_on_the_selection_half_than_on_the_report_half():
    """Nine candidates whose corrections only add noise (0.1 mm per axis on a 1 mm residual): each one's
    true shrink is 1 - sqrt(1.01) = -0.5 %. Picked on the selection half, the winner looks better
    there by luck; on the report half its shrink is the true one."""
    rng = np.random.default_rng(7)
    n = 1600
    split = split_holdout([n])
    chosen_selection, chosen_report = [], []
    for _ in range(200):
        baseline = [rng.normal(0.0, 1.0, (n, 3))]
        candidates = [[baseline[0] + rng.normal(0.0, 0.1, (n, 3))] for _ in range(9)]
        shrinks = [1 - rmse_mm(split.selected(c)) / rmse_mm(split.selected(baseline)) for c in candidates]
        best = candidates[int(np.argmax(shrinks))]
        chosen_selection.append(max(shrinks))
        chosen_report.append(1 - rmse_mm(split.reported(best)) / rmse_mm(split.reported(baseline)))
    true_shrink = 1 - np.sqrt(1.01)
    assert abs(np.mean(chosen_report) - true_shrink) < 0.001
    assert np.mean(chosen_selection) > true_shrink + 0.002
