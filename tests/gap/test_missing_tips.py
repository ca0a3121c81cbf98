"""Rows without a tip (empty tip cells: a tracker slower than the log, or a missing tool) are skipped by
every step of the diagnosis that reads tips, and nothing it computes turns non-finite."""
import numpy as np

from control.excitation import holdout_trajectory
from crest.config import load_testbed_config
from crest.experiment.workspace_from_config import limits_for, workspace_for
from crest.gap.log_recordings import load_recordings
from crest.gap.synthetic_logs import Plant, SensorNoise, record_plant_log
from model import CatheterParams
from model.gap.calibration import ModelFit, rmse_mm, tip_errors
from model.gap.holdout_split import split_holdout
from model.gap.noise import tracker_noise_mm
from model.gap.sample_features import compute_features
from model.gap.signatures import signatures
from model.gap.simulation import Resolution, predict_tips


def test_half_the_tip_cells_empty(tmp_path):
    params = CatheterParams.from_toml()
    config = load_testbed_config()
    trajectory = holdout_trajectory(workspace_for(config, params), limits_for(config), 0.05, short=True)
    path = record_plant_log(tmp_path / "holdout.csv", trajectory, Plant(params, n_elements=6),
                            SensorNoise(tip_mm=0.1, dropout_fraction=0.5), np.random.default_rng(3))
    row = path.read_text().splitlines()
    assert any(",," in line for line in row[1:]), "the log has empty tip cells"
    recording = load_recordings([path])[0]
    assert 0.4 < 1 - recording.valid.mean() < 0.6
    noise = tracker_noise_mm([recording])
    assert noise is not None and 0.05 < noise < 0.2
    resolution = Resolution(n_elements=6, fit_rate_hz=5.0)
    held = resolution.prepare([recording])
    fit = ModelFit(params, (0.0, 0.0, 0.0, 0.0), {})
    errors = tip_errors(fit, held, resolution)
    assert len(errors[0]) == held[0].valid.sum() and np.isfinite(errors[0]).all()
    split = split_holdout([len(e) for e in errors])
    assert np.isfinite(rmse_mm(split.selected(errors))) and np.isfinite(rmse_mm(split.reported(errors)))
    features = compute_features(held, fit.zero_offsets_mm, [None])
    tips = [predict_tips(params, fit.terms(), np.zeros(4), held[0], resolution)]
    signature = signatures(features, errors[0], held, tips, fit.zero_offsets_mm, noise)
    assert signature["static_hold"]["rmse_mm"] is not None and np.isfinite(signature["static_hold"]["rmse_mm"])
