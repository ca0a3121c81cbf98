"""Robustness (issue 14, item 6): a candidate whose prediction failed is never the verdict, and the JSON
never holds a non-finite number."""
import json
import math

import numpy as np

from crest.cli.gap_command import _write_json
from model.gap.calibration import ModelFit
from model.gap.candidates import evaluate, ranked
from model.gap.finite_json import finite_tree
from model.gap.holdout_split import split_holdout
from model import CatheterParams


def fit(effects):
    return ModelFit(CatheterParams.from_toml(), (0.0, 0.0, 0.0, 0.0), effects)


def test_a_failed_prediction_scores_last_and_is_marked_failed():
    rng = np.random.default_rng(0)
    baseline = [rng.normal(0.0, 1.0, (200, 3))]
    split = split_holdout([200])
    better = evaluate(("gravity",), fit({"gravity": (0.0, -9.81)}), [0.5 * baseline[0]], baseline, split)
    diverged_errors = baseline[0].copy()
    diverged_errors[150:] = np.inf        # the model diverged on the report half only
    diverged = evaluate(("backlash",), fit({"backlash": (0.4,)}), [diverged_errors], baseline, split)
    assert diverged.failed and not better.failed
    assert diverged.report_rmse_mm == math.inf and diverged.report_shrink == -math.inf
    assert ranked([diverged, better])[0] is better
    row = diverged.as_dict()
    assert row["diverged"] and row["holdout_rmse_mm"] is None and row["shrink"] is None
    json.dumps(row, allow_nan=False)


def test_non_finite_numbers_become_null_with_the_path_and_reason():
    tree, nulls = finite_tree({"verdict": {"shrink": -math.inf, "effects": ["backlash"]},
                               "candidates": [{"score": math.nan}, {"score": 0.2}]})
    assert tree == {"verdict": {"shrink": None, "effects": ["backlash"]},
                    "candidates": [{"score": None}, {"score": 0.2}]}
    assert [n["path"] for n in nulls] == ["/verdict/shrink", "/candidates/0/score"]
    assert all("not a finite number" in n["reason"] for n in nulls)


def test_the_json_writer_writes_strict_json(tmp_path):
    path = tmp_path / "gap.json"
    _write_json({"verdict": {"holdout_rmse_after_mm": math.inf}}, path)
    text = path.read_text()
    assert "Infinity" not in text and "NaN" not in text
    data = json.loads(text)
    assert data["verdict"]["holdout_rmse_after_mm"] is None
    assert data["non_finite"][0]["path"] == "/verdict/holdout_rmse_after_mm"
