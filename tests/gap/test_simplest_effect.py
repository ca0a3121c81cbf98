"""Between found effects, one with fewer parameters leads unless the best removes more error than noise
and fitting freedom explain beyond it, and the found effects the named one does not beat that way are
listed as good on these logs (model/gap/simplest_effect.py)."""
import json

from crest.cli.gap_command import format_verdict
from crest.reports.gap_report import markdown
from model.gap.candidates import CandidateResult
from model.gap.simplest_effect import as_good_as, parameter_count, simplest_sufficient
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


def test_a_sensor_offset_along_the_axis_gives_way_to_the_tube_friction_it_mimics():
    """Rod seed 82, case 17: a tube friction; from 1.323 mm on the selection half the sensor offset (three
    parameters) reached 1.044 mm, the tracker offset (three) 1.061 mm and the tube friction (one) 1.064 mm."""
    sensor, tracker, tube = found("sensor_offset", 1.044, 0.21), found("tracker_offset", 1.061, 0.20), \
        found("tube_friction", 1.064, 0.20)
    assert [parameter_count(r) for r in (sensor, tracker, tube)] == [3, 3, 1]
    assert [r.effects[0] for r in simplest_sufficient([sensor, tracker, tube], noise_mm=0.0666)] == \
        ["tube_friction", "sensor_offset", "tracker_offset"]


def test_an_effect_that_removes_meaningfully_more_than_a_simpler_one_keeps_the_lead():
    """Rod seed 82, case 4: a true sensor offset removed 0.83 of the error; a one-parameter effect at 0.43
    is not sufficient."""
    sensor, tube = found("sensor_offset", 0.17, 0.83), found("tube_friction", 0.57, 0.43)
    assert simplest_sufficient([sensor, tube], noise_mm=0.05) == [sensor, tube]


def test_of_several_sufficient_effects_the_fewest_parameters_then_the_lowest_error_lead():
    offset, gravity, lag, backlash = (found("tracker_offset", 0.600, 0.40), found("gravity", 0.601, 0.40),
                                      found("rate_lag", 0.603, 0.40), found("backlash", 0.605, 0.39))
    ranked = simplest_sufficient([offset, gravity, lag, backlash], noise_mm=0.1)
    assert [r.effects[0] for r in ranked] == ["backlash", "tracker_offset", "gravity", "rate_lag"]
    ranked = simplest_sufficient([offset, gravity, lag], noise_mm=0.1)
    assert [r.effects[0] for r in ranked] == ["gravity", "tracker_offset", "rate_lag"]


def test_the_verdict_and_the_report_say_which_richer_effect_gave_way():
    """A real diagnosis gives the field (empty: no nested pair was found); the report names the richer
    effect and why it gave way when there is one."""
    result = json.loads(json.dumps(diagnoses()[0]))
    assert result["verdict"]["simpler_than"] == []
    reason = ("rate_lag has 2 free parameters, tendon_elasticity 1, and rate_lag removes no more error than noise "
              "and fitting freedom explain beyond it (0.605 -> 0.589 mm on the selection half)")
    result["verdict"]["simpler_than"] = [{"effect": "rate_lag", "reason": reason}]
    assert f"- named before rate_lag, which scored higher: {reason}" in markdown(result)


def test_twin_offsets_that_the_logs_cannot_tell_apart_are_as_good_and_a_meaningfully_worse_effect_is_not():
    """Rod seed 112, case 2: a tracker offset; from 1.837 mm on the selection half the sensor offset reached
    1.061 mm, the tracker offset 1.079 mm (tracker noise 0.073 mm per axis). Dahl seed 53, case 4: a lag at
    0.463 mm beats the elastic line's 0.817 mm."""
    sensor, tracker = found("sensor_offset", 1.061, 0.42), found("tracker_offset", 1.079, 0.41)
    assert as_good_as(sensor, [sensor, tracker], noise_mm=0.073) == [tracker]
    lag, line = found("rate_lag", 0.463, 0.54), found("tendon_elasticity", 0.817, 0.18)
    assert as_good_as(lag, [lag, line], noise_mm=0.1) == []


def test_the_verdict_the_command_and_the_report_list_the_effects_as_good_as_the_named_one():
    result = json.loads(json.dumps(diagnoses()[0]))
    assert isinstance(result["verdict"]["as_good"], list)
    reason = ("sensor_offset removes no more error than noise and fitting freedom explain beyond it (1.079 -> "
              "1.061 mm on the selection half), so these logs cannot tell them apart")
    result["verdict"]["as_good"] = [{"effect": "tracker_offset", "selection_rmse_mm": 1.079, "reason": reason}]
    assert f"- as good on these logs: tracker_offset: {reason}" in markdown(result)
    assert f"as good on these logs: tracker_offset: {reason}" in format_verdict(result).splitlines()

