"""The blind-benchmark report (issue 6: publish the confusion matrix): Markdown and figures."""
from crest.gap.blind_benchmark import score
from crest.reports.blind_report import confusion_markdown, write_blind_report


def case(index, kind, truth, predicted, predicted_shrink, oracle):
    return {"case": index, "kind": kind, "truth": truth, "predicted": predicted or "none",
            "predicted_effects": [predicted] if predicted else [], "predicted_shrink": predicted_shrink,
            "holdout_rmse_before_mm": 1.0, "holdout_rmse_after_mm": 1.0 - predicted_shrink, "noise_floor_mm": 0.17,
            "oracle_shrink": oracle, "shrink_error_pp": 100 * abs(predicted_shrink - oracle),
            "effect_rms_mm": 0.8, "noise_mm": 0.1, "above_noise": True, "relative_size": 0.8,
            "above_detection_limit": True}


def result():
    rows = [case(0, "single", ["backlash"], "backlash", 0.9, 0.92), case(1, "single", ["gravity"], None, 0.0, 0.1),
            case(2, "none", [], None, 0.0, 0.0), {"case": 3, "kind": "single", "truth": ["torsion"],
                                                 "skipped": "the plant failed in 6 draws"}]
    return {"score": {"dahl": score(rows)}, "cases": rows,
            "settings": {"seed": 1, "excitation": "short", "path": "virtual testbed", "seconds": 600.0}}


def test_confusion_table_lists_true_effects_against_verdicts():
    table = confusion_markdown(result()["score"]["dahl"]["confusion"]).splitlines()
    assert table[0] == "| true \\ verdict | backlash | gravity | none |"
    assert "| backlash | 1 | . | . |" in table and "| gravity | . | . | 1 |" in table and "| none | . | . | 1 |" in table


def test_report_writes_markdown_and_figures(tmp_path):
    path = write_blind_report(result(), tmp_path / "blind")
    text = path.read_text()
    assert "| top-1 on single effects | 50% of 2 | - |" in text
    assert "| top-1 above the detection limit | 50% of 2 | >= 90% |" in text
    assert "| dahl | 3 | torsion | the plant failed in 6 draws |" in text
    assert "| backlash | 0.7-1 | 1 | 100% |" in text       # the detection-limit table
    # the backlash verdict takes its log down to the noise floor: confident, and right
    assert "| `confident` verdicts above the detection limit: right / wrong | 1 / 0 | - / 0 |" in text
    assert "| clean cases with a catalog effect named `confident` | 0 | 0 |" in text
    assert (tmp_path / "blind" / "confusion_dahl.png").stat().st_size > 1000
    assert (tmp_path / "blind" / "detection_dahl.png").stat().st_size > 1000
    assert (tmp_path / "blind" / "shrink.png").stat().st_size > 1000


def test_a_case_whose_oracle_failed_is_reported_as_failed_and_left_out_of_the_shrink_figure(tmp_path):
    """As on rod seed 50: the oracle's held-out prediction failed (-inf); the report stopped on it."""
    failed = dict(case(4, "single", ["tendon_elasticity"], "tendon_elasticity", 0.49, 0.0), oracle_shrink=float("-inf"))
    del failed["shrink_error_pp"]        # run_case scores no shrink error without a finite oracle
    rows = result()["cases"] + [failed]
    path = write_blind_report({**result(), "cases": rows, "score": {"dahl": score(rows)}}, tmp_path / "blind")
    assert "| dahl | 4 | tendon_elasticity | tendon_elasticity | 0.80 | 0.80 | - | 0.10 | 0.49 | failed |" in path.read_text()
    assert (tmp_path / "blind" / "shrink.png").stat().st_size > 1000


def test_the_rod_report_adds_the_detection_limit_by_the_effects_visible_part(tmp_path):
    absorbed = dict(case(0, "single", ["lumen_compression"], None, 0.0, 0.0), relative_size=5.1,
                    visible_effect_mm=0.0, visible_relative_size=0.0, above_visible_limit=False)
    seen = dict(case(1, "single", ["backlash"], "backlash", 0.95, 0.95), relative_size=0.98,
                visible_effect_mm=11.9, visible_relative_size=0.71, above_visible_limit=True)
    rows = [dict(r, family="rod") for r in (absorbed, seen)]
    text = write_blind_report({**result(), "cases": rows, "score": {"rod": score(rows)}}, tmp_path / "blind").read_text()
    assert "| top-1 above the detection limit | 50% of 2 | >= 90% |" in text
    assert ("| top-1 above the detection limit by the effect's visible part (what the calibrated model cannot "
            "absorb) | 100% of 1 | - |") in text
    assert "| lumen_compression | 0-0.1 | 1 | 0% |" in text and "| backlash | 0.7-1 | 1 | 100% |" in text
    assert "| rod | 0 | lumen_compression | none | 0.80 | 5.10 | 0.00 | 0.10 | 0.00 | 0.00 |" in text
    assert (tmp_path / "blind" / "detection_rod.png").stat().st_size > 1000
