"""The seed paper's qualitative claims (sections III-IV), checked on `crest paper`'s summary.json.

The reproduction runs once, through the command line, with the default catheter
(configs/catheter.toml) and the paper's 20 elements.
"""
import contextlib
import io
import json

import numpy as np
import pytest

from crest.cli.main import main
from crest.paper import SUMMARY
from crest.paper.reproduce import STUDIES

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def reproduction(tmp_path_factory):
    out = tmp_path_factory.mktemp("paper")
    stdout, stderr = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        code = main(["paper", "--out", str(out)])
    return {"code": code, "out": out, "stdout": stdout.getvalue(), "stderr": stderr.getvalue(),
            "summary": json.loads((out / SUMMARY).read_text())}


@pytest.fixture(scope="module")
def figures(reproduction):
    return reproduction["summary"]["figures"]


def strictly_increasing(values) -> bool:
    return bool(np.all(np.diff(values) > 0))


# -- the command ---------------------------------------------------------------------------

def test_command_writes_one_png_per_figure_and_reports_progress(reproduction):
    assert reproduction["code"] == 0
    names = [study.FIGURE for study in STUDIES]
    assert [figure["figure"] for figure in reproduction["summary"]["figures"].values()] == names
    for name in names:
        data = (reproduction["out"] / name).read_bytes()
        assert data.startswith(PNG_SIGNATURE), f"{name} is not a PNG"
        assert len(data) > 10_000, f"{name} is nearly empty ({len(data)} bytes)"
    progress = [line for line in reproduction["stderr"].splitlines() if line.startswith("crest paper [")]
    assert len(progress) == len(STUDIES)
    assert all(name in line for name, line in zip(names, progress))


# -- Fig. 3.1 ------------------------------------------------------------------------------

def test_friction_makes_curvature_larger_near_the_base(figures):
    """III: friction consumes tension along the catheter: small radius at the base, large at the tip."""
    fig = figures["fig_3_1"]
    assert fig["curvature_base_per_mm"] > 1.2 * fig["curvature_tip_per_mm"]
    assert np.all(np.diff(fig["curvature_per_mm"]) < 0), "curvature must fall from base to tip"
    # without friction the lumped model bends evenly, like constant curvature
    assert fig["frictionless_base_to_tip_ratio"] == pytest.approx(1.0, abs=0.02)
    assert fig["radius_base_mm"] < fig["constant_curvature_radius_mm"] < fig["radius_tip_mm"]


# -- Fig. 3.2 and the headline -------------------------------------------------------------

def test_the_tip_gap_to_constant_curvature_at_180_deg_is_caused_by_friction(reproduction, figures):
    fig = figures["fig_3_2"]
    assert fig["end_difference_cc_vs_friction_mm"] > 5.0
    assert fig["end_difference_cc_vs_frictionless_mm"] < 0.1 * fig["end_difference_cc_vs_friction_mm"]
    headline = reproduction["summary"]["headline"]
    assert headline["cc_vs_friction_tip_difference_at_180_deg_cm"] == pytest.approx(
        fig["end_difference_cc_vs_friction_mm"] / 10.0)
    assert "no prototype data" in headline["note"]


# -- Fig. 4.1 ------------------------------------------------------------------------------

def test_larger_mu_gives_a_larger_trajectory_that_ends_farther_from_constant_curvature(figures):
    """IV: a large friction coefficient drives the tip along a larger trajectory, away from the CC end."""
    fig = figures["fig_4_1"]
    runs = fig["per_mu"]
    assert strictly_increasing([run["mu"] for run in runs])
    assert strictly_increasing([run["end_distance_from_cc_end_mm"] for run in runs])
    assert strictly_increasing([run["path_length_mm"] for run in runs])
    assert strictly_increasing([run["max_reach_from_axis_mm"] for run in runs])
    largest = runs[-1]
    assert largest["path_length_mm"] > 1.1 * fig["constant_curvature"]["path_length_mm"]
    assert largest["end_distance_from_cc_end_mm"] > 10.0


# -- Fig. 4.2 ------------------------------------------------------------------------------

def test_friction_deflects_the_tip_off_the_constant_curvature_line_under_insertion(figures):
    """IV: at 180 deg constant curvature moves the tip on a horizontal line as the length changes."""
    fig = figures["fig_4_2"]
    assert fig["cc_line_max_abs_z_mm"] < 1e-9
    runs = fig["per_mu"]
    assert strictly_increasing([run["max_vertical_deviation_from_cc_line_mm"] for run in runs])
    assert strictly_increasing([run["vertical_deflection_span_mm"] for run in runs])
    stroke_mm = max(fig["insertion_waypoints_mm"]) - min(fig["insertion_waypoints_mm"])
    assert runs[-1]["vertical_deflection_span_mm"] > 0.1 * stroke_mm


# -- Fig. 4.3 ------------------------------------------------------------------------------

def test_deviation_from_the_commanded_circle_grows_with_articulation(figures):
    circles = figures["fig_4_3"]["per_articulation"]
    assert strictly_increasing([c["articulation_deg"] for c in circles])
    assert strictly_increasing([c["mean_distance_to_commanded_circle_mm"] for c in circles])
    assert strictly_increasing([c["max_distance_to_commanded_circle_mm"] for c in circles])


def test_circles_start_larger_than_constant_curvature_and_become_smaller(figures):
    circles = figures["fig_4_3"]["per_articulation"]
    assert circles[0]["radius_ratio_to_cc"] > 1.0
    assert circles[-1]["radius_ratio_to_cc"] < 0.98


def test_circle_deviation_is_concentrated_at_the_tendons(figures):
    """One tendon carries the whole load where the path crosses it: friction acts most there."""
    for circle in figures["fig_4_3"]["per_articulation"]:
        assert circle["radial_deviation_at_tendons_mm"] > circle["radial_deviation_between_tendons_mm"], circle


def test_circles_bulge_toward_the_tendons_while_larger_than_constant_curvature(figures):
    larger = [c for c in figures["fig_4_3"]["per_articulation"] if c["radius_ratio_to_cc"] > 1.0]
    assert len(larger) >= 2
    for circle in larger:
        assert circle["bulge_toward_tendons_mm"] > 0.02 * circle["cc_radius_mm"], circle


@pytest.mark.xfail(strict=True, reason=(
    "model disagrees with the paper (IV, Fig. 4.3b): the paper sees bulges near the wires on the circles "
    "that have become smaller than constant curvature. In our model the radius between the wires stays "
    "within 0.2 mm of constant curvature (one tendon releasing, held by friction, and one pulling: their "
    "friction cancels), and the whole deviation sits at the wires, where one tendon slides under load and "
    "the curvature is base-heavy; base-heavy curvature enlarges the circle below about 178 deg and shrinks "
    "it above, so a smaller circle is flattened at the wires"))
def test_circles_smaller_than_constant_curvature_bulge_toward_the_tendons(figures):
    smallest = figures["fig_4_3"]["per_articulation"][-1]
    assert smallest["radius_ratio_to_cc"] < 1.0
    assert smallest["bulge_toward_tendons_mm"] > 0.0


# -- Fig. 4.4 ------------------------------------------------------------------------------

def test_the_two_history_cases_move_differently(figures):
    fig = figures["fig_4_4"]
    assert fig["max_direction_difference_deg"] > 5.0
    assert fig["start_difference_mm"] > 1.0
    for move in fig["difference"].values():
        assert move["end_point_difference_mm"] > 1.0


def test_zero_friction_start_is_symmetric_and_previous_motion_is_not(figures):
    """IV: from the Dahl zero crossing friction grows alike both ways; after motion it does not."""
    cases = figures["fig_4_4"]["cases"]
    fresh, loaded = cases["without_previous_motion"], cases["with_previous_motion"]
    assert fresh["reversal_asymmetry_deg"] < 2.0
    assert fresh["reversal_step_ratio"] == pytest.approx(1.0, abs=0.02)
    assert loaded["reversal_asymmetry_deg"] > fresh["reversal_asymmetry_deg"] + 5.0
    assert abs(loaded["reversal_step_ratio"] - 1.0) > 0.1
