"""Between a found effect and a simpler one it reduces to, the simpler one leads unless the richer one
removes more error than noise and fitting freedom explain (model/gap/nested_candidates.py)."""
import json

from crest.reports.gap_report import markdown
from model.effects import EFFECTS
from model.gap.candidates import CandidateResult
from model.gap.nested_candidates import simplest_sufficient
from tests.gap.test_sampling import diagnoses


def found(effect_id: str, selection_rmse_mm: float, score: float) -> CandidateResult:
    return CandidateResult(effects=(effect_id,), fit=None, holdout_rmse_mm=selection_rmse_mm, holdout_errors=(),
                           shrink=0.0, signature_match=1.0, score=score, report_rmse_mm=selection_rmse_mm,
                           report_shrink=0.0)


def test_a_lag_that_removes_no_more_than_an_elastic_line_gives_way_to_it():
    """Rod seed 71, case 8: an elastic drive line; the lag reached 0.589 mm, the line 0.605 mm."""
    lag, line, offset = found("rate_lag", 0.589, 0.36), found("tendon_elasticity", 0.605, 0.34), \
        found("tracker_offset", 0.85, 0.07)
    assert [r.effects[0] for r in simplest_sufficient([lag, line, offset], noise_mm=0.1)] == \
        ["tendon_elasticity", "rate_lag", "tracker_offset"]


def test_a_lag_that_removes_meaningfully_more_keeps_the_lead():
    """Dahl seed 53, case 4: a true lag removed 0.537 of the error, the elastic line 0.183."""
    lag, line = found("rate_lag", 0.463, 0.54), found("tendon_elasticity", 0.817, 0.18)
    assert simplest_sufficient([lag, line], noise_mm=0.1) == [lag, line]


def test_without_the_simpler_effect_found_the_order_stands():
    lag, offset = found("rate_lag", 0.589, 0.36), found("tracker_offset", 0.6, 0.3)
    assert simplest_sufficient([lag, offset], noise_mm=0.1) == [lag, offset]
    assert simplest_sufficient([], noise_mm=0.1) == []


def test_every_reduction_names_a_catalog_effect_with_fewer_parameters():
    for effect in EFFECTS.values():
        if effect.reduces_to:
            assert len(EFFECTS[effect.reduces_to].param_names) < len(effect.param_names), effect.id


def test_the_verdict_and_the_report_say_which_richer_effect_gave_way():
    """A real diagnosis gives the field (empty: no nested pair was found); the report names the richer
    effect and why it gave way when there is one."""
    result = json.loads(json.dumps(diagnoses()[0]))
    assert result["verdict"]["simpler_than"] == []
    result["verdict"]["simpler_than"] = [{"effect": "rate_lag", "reason": "rate_lag reduces to tendon_elasticity "
                                          "and removes no more error than noise and fitting freedom explain"}]
    assert ("- named before rate_lag, which scored higher: rate_lag reduces to tendon_elasticity and removes no more "
            "error than noise and fitting freedom explain") in markdown(result)
