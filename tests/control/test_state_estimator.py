"""Issue 5, claim 3: the estimator rides through dropouts, gates bad samples, and a lost tracker stops the loop."""
import math

import numpy as np
import pytest

from control import DahlFeedback, SampleStatus, TipEstimator, TipMeasurement, TrackerLostError, make_controller
from control.friction_sensitivity import ModelPrediction
from control.trajectories import articulation_sweep
from tests.control.closed_loop import CONTROLLER_ELEMENTS, make_plant, run_loop

PERIOD_S = 0.01


def test_tip_estimate_within_1mm_rms_with_20_percent_dropout_and_03mm_noise(params, workspace, limits):
    trajectory = articulation_sweep(workspace, limits, angle_rad=math.radians(150), plane_rad=0.6,
                                    velocity_rad_s=1.5, acceleration_rad_s2=4.0, hold_s=0.5)
    controller = make_controller("dahl+fb", workspace, limits, n_elements=CONTROLLER_ELEMENTS)
    record = run_loop(controller, trajectory, make_plant(params), noise_mm=0.3, dropout=0.2, seed=7)
    error = np.linalg.norm(record.estimate_mm - record.tip_mm, axis=1)
    rms = float(np.sqrt(np.mean(error ** 2)))
    raw_rms = 0.3 * math.sqrt(3)   # RMS distance of a raw tracker sample from the true tip
    print(f"estimator tip RMS error {rms:.3f} mm (raw samples {raw_rms:.3f} mm), "
          f"counts {controller.estimator.counts}")
    assert controller.estimator.counts[SampleStatus.ACCEPTED] < 0.9 * len(trajectory)   # the dropouts happened
    assert rms < 1.0
    assert rms < raw_rms


def prediction(tip=(10.0, 0.0, 70.0), tip_slope=(1.0, 0.0, -0.5), tension=(8.0, 4.0, 1.0, 4.0),
               tension_slope=(5.0, 2.0, 1.0, 2.0)) -> ModelPrediction:
    return ModelPrediction(np.array(tip), np.array(tension), np.array(tip_slope), np.array(tension_slope))


def feed(estimator, predicted, true_tip, cycles, rng, start_s=0.0, noise_mm=0.3):
    for k in range(cycles):
        now = start_s + (k + 1) * PERIOD_S
        estimator.predict(predicted, PERIOD_S)
        estimator.update_tip(TipMeasurement(true_tip + rng.normal(0, noise_mm, 3), now - 0.005), now)
    return start_s + cycles * PERIOD_S


def test_covariance_grows_through_a_dropout_and_shrinks_when_samples_return():
    rng = np.random.default_rng(0)
    estimator = TipEstimator()
    predicted = prediction()
    now = feed(estimator, predicted, predicted.tip_mm + [0.8, -0.5, 0.2], 100, rng)
    spread = [np.trace(estimator.tip_covariance_mm2)]
    for _ in range(30):
        estimator.predict(predicted, PERIOD_S)
        spread.append(np.trace(estimator.tip_covariance_mm2))
    assert np.all(np.diff(spread) > 0)
    feed(estimator, predicted, predicted.tip_mm + [0.8, -0.5, 0.2], 20, rng, start_s=now + 0.3)
    assert np.trace(estimator.tip_covariance_mm2) < 0.5 * spread[-1]
    assert np.linalg.norm(estimator.tip_mm - (predicted.tip_mm + [0.8, -0.5, 0.2])) < 0.3


def test_outlier_is_gated_and_does_not_move_the_estimate():
    rng = np.random.default_rng(1)
    estimator = TipEstimator()
    predicted = prediction()
    now = feed(estimator, predicted, predicted.tip_mm, 100, rng)
    before = estimator.tip_mm
    estimator.predict(predicted, PERIOD_S)
    status = estimator.update_tip(TipMeasurement(predicted.tip_mm + [15.0, 0.0, 0.0], now), now + PERIOD_S)
    assert status is SampleStatus.OUTLIER
    assert np.linalg.norm(estimator.tip_mm - before) < 0.05
    good = estimator.update_tip(TipMeasurement(predicted.tip_mm, now + PERIOD_S), now + PERIOD_S)
    assert good is SampleStatus.ACCEPTED


def test_repeated_and_stale_samples_are_not_fused():
    rng = np.random.default_rng(2)
    estimator = TipEstimator(max_sample_age_s=0.1)
    predicted = prediction()
    now = feed(estimator, predicted, predicted.tip_mm, 50, rng)
    before = estimator.tip_mm.copy()
    last = TipMeasurement(predicted.tip_mm + [2.0, 0, 0], now - 0.005)
    assert estimator.update_tip(last, now) is SampleStatus.REPEAT
    old = TipMeasurement(predicted.tip_mm + [2.0, 0, 0], now)
    assert estimator.update_tip(old, now + 0.2) is SampleStatus.STALE
    assert np.array_equal(estimator.tip_mm, before)
    assert estimator.last_valid_time_s == pytest.approx(now - 0.005)


def test_drive_tensions_reveal_the_friction_scale():
    """Tensions z = t + (s - 1) g_T: with s = 1.3 the filter's friction scale converges to 1.3.

    Good samples are gated with the designed probability (1e-3) only."""
    rng = np.random.default_rng(3)
    estimator = TipEstimator(tension_noise_n=0.2, gate_probability=1e-3)
    predicted = prediction()
    for _ in range(200):
        estimator.predict(predicted, PERIOD_S)
        measured = predicted.drive_tension_n + 0.3 * predicted.tension_per_friction_scale_n + rng.normal(0, 0.2, 4)
        estimator.update_tension(measured)
    assert estimator.counts[SampleStatus.ACCEPTED] >= 198
    assert estimator.friction_scale == pytest.approx(1.3, abs=0.03)


def test_tracker_loss_longer_than_the_timeout_stops_the_closed_loop(params, workspace, limits):
    trajectory = articulation_sweep(workspace, limits, angle_rad=math.radians(60), velocity_rad_s=1.0,
                                    acceleration_rad_s2=4.0, hold_s=1.0)
    controller = DahlFeedback(workspace, limits, PERIOD_S, n_elements=CONTROLLER_ELEMENTS, loss_timeout_s=0.25)
    plant = make_plant(params)
    last_sample_s = None
    commanded = 0
    with pytest.raises(TrackerLostError, match="no valid tip sample"):
        for k, setpoint in enumerate(trajectory):
            sample = None
            if k < 20:
                last_sample_s = setpoint.t_s - 0.005
                sample = TipMeasurement(plant.tip_mm, last_sample_s)
            command = controller.command(setpoint, sample)
            plant.move_to(command.tendon_mm, command.insertion_mm)
            commanded += 1
    stopped_at_s = trajectory.t_s[commanded]
    assert stopped_at_s - last_sample_s > 0.25
    assert stopped_at_s - last_sample_s <= 0.25 + PERIOD_S + 1e-9


def test_a_stream_of_outliers_counts_as_tracker_loss(params, workspace, limits):
    trajectory = articulation_sweep(workspace, limits, angle_rad=math.radians(60), velocity_rad_s=1.0,
                                    acceleration_rad_s2=4.0, hold_s=1.0)
    controller = DahlFeedback(workspace, limits, PERIOD_S, n_elements=CONTROLLER_ELEMENTS, loss_timeout_s=0.25)
    plant = make_plant(params)
    with pytest.raises(TrackerLostError):
        for k, setpoint in enumerate(trajectory):
            offset = np.array([0.0, 0.0, 40.0]) if k >= 20 else np.zeros(3)
            command = controller.command(setpoint, TipMeasurement(plant.tip_mm + offset, setpoint.t_s - 0.005))
            plant.move_to(command.tendon_mm, command.insertion_mm)
    assert controller.estimator.counts[SampleStatus.OUTLIER] >= 20


def test_a_consistent_shift_of_a_few_mm_is_reacquired_after_three_samples():
    """A real, sudden model error (e.g. backlash at a reversal) is not gated forever."""
    rng = np.random.default_rng(4)
    estimator = TipEstimator(reacquire_after=3)
    predicted = prediction()
    now = feed(estimator, predicted, predicted.tip_mm, 100, rng)
    shifted = predicted.tip_mm + [0.0, 4.0, 0.0]
    statuses = []
    for k in range(10):
        now += PERIOD_S
        estimator.predict(predicted, PERIOD_S)
        statuses.append(estimator.update_tip(TipMeasurement(shifted + rng.normal(0, 0.3, 3), now - 0.005), now))
    assert statuses[:2] == [SampleStatus.OUTLIER] * 2
    assert statuses[2] is SampleStatus.REACQUIRED
    assert np.linalg.norm(estimator.tip_mm - shifted) < 0.5
