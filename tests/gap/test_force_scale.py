"""The force scale the tips leave free, set from logged drive tensions (model.gap.force_scale)."""
import dataclasses

import numpy as np
import pytest

from model import CatheterParams
from model.gap.calibration import ModelFit, calibrate
from model.gap.force_scale import SCALED, force_scale, scaled_to_tensions
from model.gap.simulation import predict_tips_and_tension
from tests.gap.test_calibration import RESOLUTION, noiseless_recording

ZEROS = (0.0, 0.0, 0.0, 0.0)


@pytest.fixture(scope="module")
def truth_and_log():
    truth = CatheterParams.from_toml()
    recording = noiseless_recording(truth)
    _, tension = predict_tips_and_tension(truth, ModelFit(truth, ZEROS, {}).terms(), np.zeros(4), recording,
                                          RESOLUTION)
    return truth, dataclasses.replace(recording, tendon_force_n=tension)


def test_a_fit_twice_too_stiff_is_scaled_back_by_the_logged_tensions(truth_and_log):
    truth, log = truth_and_log
    stiff = ModelFit(truth.replace(**{name: 2.0 * getattr(truth, name) for name in SCALED}), ZEROS, {})
    assert 0.5 < force_scale(stiff, [log], RESOLUTION) < 0.9    # one step: the pretension does not scale
    back, scale = scaled_to_tensions(stiff, [log], RESOLUTION)
    assert scale == pytest.approx(0.5, rel=0.02)
    for name in SCALED[:4]:
        assert getattr(back.params, name) == pytest.approx(getattr(truth, name), rel=0.02)
    assert back.params.mu == truth.mu and back.params.tendon_offset_mm == truth.tendon_offset_mm


def test_without_logged_tensions_there_is_no_scale(truth_and_log):
    truth, log = truth_and_log
    assert scaled_to_tensions(ModelFit(truth, ZEROS, {}), [dataclasses.replace(log, tendon_force_n=None)],
                              RESOLUTION) is None


def test_a_fit_on_logged_tensions_finds_the_scale_that_tips_alone_leave(truth_and_log):
    """From a start twice too stiff, the tips alone keep the fit near that scale; the logged tensions'
    residual (`model.gap.tension_scale`) brings its tensions, and so its stiffness, back to the catheter's.
    Both fits end on the tips alike (0.09 mm: a local minimum, not the truth, from this start)."""
    truth, log = truth_and_log
    stiff = truth.replace(**{name: 2.0 * getattr(truth, name) for name in SCALED[:4]})
    tips_only = calibrate([dataclasses.replace(log, tendon_force_n=None)], stiff, prior=truth,
                          resolution=RESOLUTION, max_iterations=15)
    with_tensions = calibrate([log], stiff, prior=truth, resolution=RESOLUTION, max_iterations=15)
    assert tips_only.train_rmse_mm < 0.1 and with_tensions.train_rmse_mm < 0.1
    assert force_scale(tips_only, [log], RESOLUTION) < 0.7
    assert tips_only.params.bending_stiffness_nmm2 > 1.5 * truth.bending_stiffness_nmm2
    assert force_scale(with_tensions, [log], RESOLUTION) == pytest.approx(1.0, abs=0.02)
    assert with_tensions.params.bending_stiffness_nmm2 == pytest.approx(truth.bending_stiffness_nmm2, rel=0.2)
