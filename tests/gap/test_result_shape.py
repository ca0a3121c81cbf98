"""The diagnosis result has the documented JSON shape (issue 6, step 5) and is strict JSON."""
import json

from tests.gap.conftest import diagnosed


def test_result_matches_the_documented_json_shape():
    result = json.loads(json.dumps(diagnosed(None), allow_nan=False))
    baseline = result["baseline"]
    assert isinstance(baseline["train_rmse_mm"], float) and isinstance(baseline["holdout_rmse_mm"], float)
    assert result["where"], "at least one region"
    for row in result["where"]:
        assert isinstance(row["region"], str) and row["rmse_mm"] >= 0.0 and 0.0 <= row["share"] <= 1.0
    groups = {row["group"] for row in result["where"]}
    assert {"articulation", "plane", "insertion", "motion", "speed", "tension", "time"} <= groups
    for group in groups:   # regions of a group do not overlap: their shares add up to the whole error
        total = sum(row["share"] for row in result["where"] if row["group"] == group)
        assert total <= 1.0 + 1e-9
    assert {c["effect"] for c in result["candidates"]} == {
        "tendon_elasticity", "backlash", "lumen_compression", "tube_friction", "gravity", "torsion",
        "tracker_offset", "sensor_offset", "rate_friction", "precurvature", "rate_lag"}
    for c in result["candidates"]:
        assert isinstance(c["params"], dict) and isinstance(c["holdout_rmse_mm"], float)
        assert isinstance(c["shrink"], float)
    verdict = result["verdict"]
    assert isinstance(verdict["effect"], str) and isinstance(verdict["effects"], list)
    assert isinstance(verdict["holdout_rmse_before_mm"], float) and isinstance(verdict["holdout_rmse_after_mm"], float)
    assert 0.0 <= verdict["shrink"] <= 1.0
    assert verdict["confidence"] in ("confident", "partial", None) and "confidence_line" in verdict
    cc = result["constant_curvature"]      # the calibrated reference, on the same rows
    assert isinstance(cc["holdout_rmse_mm"], float) and len(cc["zero_offsets_mm"]) == 4
    assert [row["recording"] for row in result["holdout_by_recording"]] == result["settings"]["holdout"]
    for row in result["holdout_by_recording"]:
        assert all(isinstance(row[key], float) for key in ("constant_curvature_mm", "baseline_mm", "verdict_mm"))


def test_shares_of_the_time_bins_add_up_to_one():
    """The time bins cover every held-out sample exactly once."""
    rows = [row for row in diagnosed(None)["where"] if row["group"] == "time"]
    assert abs(sum(row["share"] for row in rows) - 1.0) < 1e-9
    assert abs(sum(row["sample_fraction"] for row in rows) - 1.0) < 1e-9
