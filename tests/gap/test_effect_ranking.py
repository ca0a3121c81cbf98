"""The diagnosis names the effect a plant has (issue 6, Tests): each candidate alone is ranked first,
and a clean plant gives `none`. The logs come from a model plant that differs from the prior catheter
in its base parameters, with tracker noise; the diagnosis sees only the log files."""
import pytest

from model.effects import EFFECTS
from tests.gap.conftest import diagnosed


@pytest.mark.parametrize("effect_id", list(EFFECTS))
def test_effect_alone_in_the_plant_is_ranked_first(effect_id):
    result = diagnosed(effect_id)
    ranking = [c["effect"] for c in result["candidates"]]
    assert ranking[0] == effect_id, f"ranking {ranking[:3]}"
    assert result["verdict"]["effect"] == effect_id
    best = result["candidates"][0]
    assert best["holdout_rmse_mm"] < result["baseline"]["report_rmse_mm"]    # both on the report half


def test_clean_plant_gives_none():
    result = diagnosed(None)
    verdict = result["verdict"]
    assert verdict["effect"] == "none" and verdict["effects"] == []
    assert verdict["shrink"] == 0.0 and verdict["confidence"] is None
    assert verdict["holdout_rmse_after_mm"] == verdict["holdout_rmse_before_mm"]
    # the calibrated base model alone is at the noise floor: nothing left to explain
    assert result["baseline"]["holdout_rmse_mm"] < 1.5 * result["baseline"]["noise_floor_mm"]
    assert verdict["residual"], "an unexplained residual is described"
