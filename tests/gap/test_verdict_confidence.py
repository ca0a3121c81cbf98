"""The verdict's grade (issue 14, "never a confident catalog effect" where the catalog holds nothing):
`confident` where the named effects at least halve the report half's held-out error above the
tracker's noise floor, `partial` below, no grade where nothing is named."""
import math

import pytest

from crest.cli.gap_command import format_verdict
from model.gap.verdict_confidence import CONFIDENT, PARTIAL, confidence, confidence_line, explained_share
from tests.gap.conftest import diagnosed


def test_nothing_named_has_no_grade():
    assert confidence([], 2.0, 2.0, 0.2) is None and confidence_line([], 2.0, 2.0, 0.2) is None


def test_an_effect_that_halves_the_error_is_confident_and_one_that_removes_less_is_partial():
    assert explained_share(2.0, 1.0, None) == 0.5 and confidence(["backlash"], 2.0, 1.0, None) == CONFIDENT
    assert confidence(["backlash"], 2.0, 1.02, None) == PARTIAL


def test_the_noise_floor_is_no_part_of_the_gap():
    """0.240 -> 0.183 mm against a 0.164 mm floor: a shrink of 24 %, but the error above the floor goes
    from sqrt(0.240^2 - 0.164^2) = 0.175 to sqrt(0.183^2 - 0.164^2) = 0.081 mm, 54 % of it removed."""
    assert explained_share(0.240, 0.183, 0.164) == pytest.approx(
        1 - math.sqrt(0.183 ** 2 - 0.164 ** 2) / math.sqrt(0.240 ** 2 - 0.164 ** 2))
    assert confidence(["gravity"], 0.240, 0.183, 0.164) == CONFIDENT
    assert explained_share(0.240, 0.150, 0.164) == 1.0        # down to the floor: all of the gap
    assert explained_share(0.150, 0.140, 0.164) == 0.0        # nothing above the floor to remove


def test_a_partial_grade_says_how_much_of_the_gap_stays():
    line = confidence_line(["tendon_elasticity"], 2.48, 2.0, 0.2)
    assert line.startswith("partial: tendon_elasticity removes 19 % of the held-out error above the 0.200 mm "
                           "noise floor on the report half")
    assert "1.990 mm RMS of the gap stays" in line


def test_a_verdict_that_makes_the_report_half_worse_says_so():
    """Rod seed 96, case 8: a sheath compression (out of catalog) named `rate_lag`, selected on the even
    blocks, made the odd blocks' error larger (report shrink -0.055)."""
    line = confidence_line(["rate_lag"], 0.80, 0.85, 0.1)
    assert line.startswith("partial: rate_lag makes the held-out error above the 0.100 mm noise floor on the "
                           "report half 6 % larger (it was selected on the other half)")
    assert "removes" not in line and "stays, all of it" in line


def test_a_pair_is_graded_on_its_joint_errors():
    assert confidence(["precurvature", "tracker_offset"], 1.0, 0.45, None) == CONFIDENT
    assert confidence_line(["precurvature", "tracker_offset"], 1.0, 0.45, None).startswith(
        "confident: precurvature + tracker_offset removes 55 %")


def test_a_diagnosed_backlash_is_confident_and_a_clean_plant_has_no_grade():
    """The fixed-seed cases of the effect rankings (a Dahl plant, in family): a gear play alone is most of
    the gap; a clean plant's verdict names nothing. The printed verdict carries the grade's line."""
    backlash, clean = diagnosed("backlash")["verdict"], diagnosed(None)["verdict"]
    assert backlash["confidence"] == CONFIDENT and backlash["shrink"] >= 0.5
    assert backlash["confidence_line"] in format_verdict(diagnosed("backlash")).splitlines()
    assert clean["confidence"] is None and clean["confidence_line"] is None
    assert not any(line.startswith(("confident:", "partial:")) for line in format_verdict(diagnosed(None)).splitlines())
