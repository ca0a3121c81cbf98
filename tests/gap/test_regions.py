"""Where the gap lies: region breakdown and motion classes (issue 6, step 2)."""
import numpy as np
import pytest

from model.gap.recording import Recording
from model.gap.regions import breakdown, concentrated, regions, shrink_by_region
from model.gap.sample_features import SampleFeatures, compute_features


def features(articulation_deg: np.ndarray) -> SampleFeatures:
    n = len(articulation_deg)
    return SampleFeatures(articulation_deg=articulation_deg, plane_deg=np.zeros(n), insertion_mm=np.full(n, 80.0),
                          motion=np.array(["loading"] * n), speed_mm_s=np.full(n, 1.0),
                          tension_n=np.linspace(1.0, 10.0, n), time_fraction=np.linspace(0.0, 1.0, n),
                          recording=np.zeros(n, dtype=int))


def test_error_confined_to_high_articulation_is_named_there():
    articulation = np.r_[np.full(50, 10.0), np.full(50, 100.0)]
    errors = np.zeros((100, 3))
    errors[50:, 0] = 1.0
    rows = breakdown(regions(features(articulation)), errors)
    by_name = {row["region"]: row for row in rows}
    high = by_name["articulation 75-105 deg"]
    assert high["share"] == pytest.approx(1.0) and high["rmse_mm"] == pytest.approx(1.0)
    assert high["concentration"] == pytest.approx(2.0)       # all the error in half the samples
    assert by_name["articulation 0-15 deg"]["share"] == 0.0
    assert concentrated(rows)[0]["region"] == "articulation 75-105 deg"


def test_shrink_by_region_compares_the_same_samples():
    found = regions(features(np.r_[np.full(50, 10.0), np.full(50, 100.0)]))
    before = np.ones((100, 3))
    after = before.copy()
    after[50:] *= 0.5
    rows = {row["region"]: row for row in shrink_by_region(found, before, after)}
    assert rows["articulation 75-105 deg"]["shrink"] == pytest.approx(0.5)
    assert rows["articulation 0-15 deg"]["shrink"] == pytest.approx(0.0)


def test_motion_classes_of_a_sweep_and_a_hold():
    """A sweep through straight to both sides, then a hold: passing straight is no reversal, the peaks are."""
    t = np.arange(0, 20.0, 0.1)
    theta = np.where(t < 10.0, np.radians(60.0) * np.sin(2 * np.pi * 0.1 * t), 0.0)
    r = 2.5
    tendon = np.column_stack([r * theta, np.zeros_like(t), -r * theta, np.zeros_like(t)])
    recording = Recording("sweep", t, tendon, np.full(len(t), 80.0), np.zeros((len(t), 3)), None, 100.0, r, 6.0)
    motion = compute_features([recording], (0.0, 0.0, 0.0, 0.0), [np.zeros((len(t), 4))]).motion
    at = {round(v, 1): m for v, m in zip(t, motion)}
    assert at[1.0] == "loading" and at[4.0] == "unloading"       # out to +60 deg, back toward straight
    assert at[4.8] == "unloading" and at[5.2] == "loading"       # through straight: no reversal
    assert at[2.7] == "after reversal" and at[7.7] == "after reversal"   # just past the peaks at 2.5 s and 7.5 s
    assert at[15.0] == "static"
