"""A plant whose drive line creeps (rate_lag): the diagnosis names it, recovers its time constant and
measures how much of the held-out error it explains (issue 16, short fixed-seed case)."""
import pytest

from model.effects import EFFECTS
from tests.gap.conftest import diagnosed


def test_rate_lag_plant_is_diagnosed_as_rate_lag_with_its_time_constant():
    result = diagnosed("rate_lag")
    verdict = result["verdict"]
    assert verdict["effect"] == "rate_lag", [c["effect"] for c in result["candidates"]][:3]
    compliance, time_s = EFFECTS["rate_lag"].typical
    fitted = verdict["params"]["rate_lag"]
    assert fitted["time_s"] == pytest.approx(time_s, rel=0.3)
    assert fitted["compliance_mm_per_n"] == pytest.approx(compliance, rel=0.3)
    # the lag is most of the held-out error: the shrink is measured and large
    assert verdict["shrink"] > 0.5
    assert verdict["holdout_rmse_after_mm"] < 2.0 * result["baseline"]["noise_floor_mm"]
    # rate friction (the other rate-dependent candidate) explains clearly less
    by_effect = {c["effect"]: c["holdout_rmse_mm"] for c in result["candidates"]}
    assert by_effect["rate_friction"] > 1.5 * by_effect["rate_lag"]
