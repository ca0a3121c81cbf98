"""Tip and friction-state estimation: an extended Kalman filter around the model's prediction.

State x = (b_x, b_y, b_z, s): the tip bias b [mm] (what the model misses: parameter error,
unmodelled effects, tracker registration) and the friction scale s [-] (control.friction_sensitivity).
The model's prediction after the command sent is the process model; the state itself walks:

    x_k = x_k-1 + w,   Q = diag(q_b, q_b, q_b, q_s) T            (T: SYNC period)

Measurements, with the model's tip p, drive tensions t and their slopes g = dp/ds, g_T = dt/ds:

    tip sample:      z = p + (s - 1) g + b + v,    H = [I_3 | g],    R = sigma_tip^2 I_3
    drive tensions:  z = t + (s - 1) g_T + v,      H = [0 | g_T],    R = sigma_T^2 I_4

Estimate of the tip: p + (s - 1) g + b, covariance H P H^T. Without samples (tracker
dropout) only Q is added, so the covariance grows. A sample is not trusted when it is a
repeat (its time does not advance), stale (older than max_sample_age_s), not finite, or an
outlier: squared Mahalanobis distance d^2 = y^T S^-1 y, y = z - h(x), S = H P H^T + R,
above the chi-square quantile chi2_m(1 - gate_probability). The update itself is filterpy's
ExtendedKalmanFilter (Joseph form).

Re-acquisition: a true, sudden model error (e.g. drive-train backlash at a reversal) looks like
a run of outliers that agree with each other. After `reacquire_after` consecutive gated tip
samples whose innovations lie within 5 sigma_tip of their mean, and whose mean is at most
max_reacquire_mm, the bias covariance is widened by diag(y^2) and the sample is fused
(REACQUIRED). A larger persistent disagreement stays gated, so the run stops on tracker loss.
"""
from __future__ import annotations

import enum
import math

import numpy as np

from control.friction_sensitivity import ModelPrediction
from control.tip_measurement import TipMeasurement


class SampleStatus(enum.Enum):
    ACCEPTED = "accepted"
    REPEAT = "repeat"
    STALE = "stale"
    INVALID = "invalid"
    OUTLIER = "outlier"
    REACQUIRED = "reacquired"
    NO_PREDICTION = "no prediction"


class TipEstimator:
    """tip_noise_mm, tension_noise_n: measurement standard deviations (per axis / per tendon).
    bias_walk_mm2_per_s, scale_walk_per_s: random-walk intensities q_b [mm^2/s] and q_s [1/s].
    initial_bias_sd_mm, initial_scale_sd: prior standard deviations at reset.
    gate_probability: chance that a good sample is gated as an outlier.
    max_sample_age_s: older samples are stale.
    reacquire_after, max_reacquire_mm: re-acquisition after a consistent run of outliers (above).
    """

    def __init__(self, *, tip_noise_mm: float = 0.3, tension_noise_n: float = 0.5, bias_walk_mm2_per_s: float = 2.0,
                 scale_walk_per_s: float = 1e-3, initial_bias_sd_mm: float = 3.0, initial_scale_sd: float = 0.3,
                 gate_probability: float = 1e-3, max_sample_age_s: float = 0.1, reacquire_after: int = 3,
                 max_reacquire_mm: float = 10.0):
        # Imported here, not with the module: filterpy imports scipy.stats and matplotlib (about a second),
        # which only a controller that builds an estimator (dahl+fb) should pay at its start.
        from filterpy.kalman import ExtendedKalmanFilter
        from scipy.stats import chi2

        values = dict(tip_noise_mm=tip_noise_mm, tension_noise_n=tension_noise_n,
                      bias_walk_mm2_per_s=bias_walk_mm2_per_s, scale_walk_per_s=scale_walk_per_s,
                      initial_bias_sd_mm=initial_bias_sd_mm, initial_scale_sd=initial_scale_sd,
                      max_sample_age_s=max_sample_age_s, max_reacquire_mm=max_reacquire_mm)
        for name, value in values.items():
            if not math.isfinite(value) or value <= 0:
                raise ValueError(f"estimator setting {name} must be a finite number > 0, got {value!r}")
        if not 0 < gate_probability < 1:
            raise ValueError(f"gate_probability must lie in (0, 1), got {gate_probability!r}")
        self.tip_noise_mm = float(tip_noise_mm)
        self.tension_noise_n = float(tension_noise_n)
        self.walk = np.diag([bias_walk_mm2_per_s] * 3 + [scale_walk_per_s])
        self.initial_covariance = np.diag([initial_bias_sd_mm ** 2] * 3 + [initial_scale_sd ** 2])
        self.tip_gate = float(chi2.ppf(1.0 - gate_probability, 3))
        self.tension_gate = float(chi2.ppf(1.0 - gate_probability, 4))
        self.max_sample_age_s = float(max_sample_age_s)
        if isinstance(reacquire_after, bool) or not isinstance(reacquire_after, int) or reacquire_after < 2:
            raise ValueError(f"reacquire_after must be an integer >= 2, got {reacquire_after!r}")
        self.reacquire_after = reacquire_after
        self.max_reacquire_mm = float(max_reacquire_mm)
        self.filter = ExtendedKalmanFilter(dim_x=4, dim_z=3)
        self.reset()

    def reset(self, time_s: float = 0.0) -> None:
        """Bias 0, friction scale 1, prior covariance; the loss clock starts at time_s."""
        self.filter.x = np.array([[0.0], [0.0], [0.0], [1.0]])
        self.filter.P = self.initial_covariance.copy()
        self.prediction: ModelPrediction | None = None
        self.last_sample_time_s = -math.inf
        self.last_valid_time_s = float(time_s)
        self.counts = {status: 0 for status in SampleStatus}
        self._gated_innovations: list[np.ndarray] = []

    # -- process -----------------------------------------------------------------------
    def predict(self, prediction: ModelPrediction, dt_s: float) -> None:
        """The model has been driven with the command sent: its prediction becomes the process model."""
        self.prediction = prediction
        self.filter.Q = self.walk * dt_s
        self.filter.predict()

    # -- measurements ------------------------------------------------------------------
    def update_tip(self, sample: TipMeasurement, now_s: float) -> SampleStatus:
        """Fuse one tracker sample taken at sample.time_s, unless it is a repeat, stale, invalid or an outlier."""
        if self.prediction is None:
            return self._count(SampleStatus.NO_PREDICTION)
        if not sample.time_s > self.last_sample_time_s:
            return self._count(SampleStatus.REPEAT)
        self.last_sample_time_s = sample.time_s
        if now_s - sample.time_s > self.max_sample_age_s:
            return self._count(SampleStatus.STALE)
        z = np.asarray(sample.tip_mm, dtype=float).reshape(-1)
        if z.shape != (3,) or not np.isfinite(z).all():
            return self._count(SampleStatus.INVALID)
        jacobian, noise = self._tip_jacobian(), self.tip_noise_mm ** 2 * np.eye(3)
        if self._fuse(z, jacobian, self._tip_model, noise, self.tip_gate):
            status = SampleStatus.ACCEPTED
        else:
            self._gated_innovations.append(z - self._tip_model(self.filter.x).ravel())
            status = SampleStatus.OUTLIER
            if self._consistent_run():
                self.filter.P[:3, :3] += np.diag(self._gated_innovations[-1] ** 2)
                self._fuse(z, jacobian, self._tip_model, noise, math.inf)
                status = SampleStatus.REACQUIRED
        if status is not SampleStatus.OUTLIER:
            self._gated_innovations.clear()
            self.last_valid_time_s = float(sample.time_s)
        return self._count(status)

    def _consistent_run(self) -> bool:
        run = self._gated_innovations[-self.reacquire_after:]
        if len(run) < self.reacquire_after:
            return False
        mean = np.mean(run, axis=0)
        spread = max(float(np.linalg.norm(y - mean)) for y in run)
        return spread <= 5.0 * self.tip_noise_mm and float(np.linalg.norm(mean)) <= self.max_reacquire_mm

    def update_tension(self, drive_tension_n) -> SampleStatus:
        """Fuse the drives' tendon tensions (N), which mostly inform the friction scale."""
        if self.prediction is None:
            return self._count(SampleStatus.NO_PREDICTION)
        z = np.asarray(drive_tension_n, dtype=float).reshape(-1)
        if z.shape != (4,) or not np.isfinite(z).all():
            return self._count(SampleStatus.INVALID)
        jacobian = np.zeros((4, 4))
        jacobian[:, 3] = self.prediction.tension_per_friction_scale_n
        fused = self._fuse(z, jacobian, self._tension_model, self.tension_noise_n ** 2 * np.eye(4), self.tension_gate)
        return self._count(SampleStatus.ACCEPTED if fused else SampleStatus.OUTLIER)

    def _fuse(self, z: np.ndarray, jacobian: np.ndarray, model, noise: np.ndarray, gate: float) -> bool:
        """The EKF update with z, unless d^2 exceeds the gate; whether it was fused."""
        innovation = z - model(self.filter.x).ravel()
        covariance = jacobian @ self.filter.P @ jacobian.T + noise
        if innovation @ np.linalg.solve(covariance, innovation) > gate:
            return False
        self.filter.update(z.reshape(-1, 1), lambda x: jacobian, model, R=noise)
        return True

    def _count(self, status: SampleStatus) -> SampleStatus:
        self.counts[status] += 1
        return status

    def _tip_jacobian(self) -> np.ndarray:
        jacobian = np.zeros((3, 4))
        jacobian[:, :3] = np.eye(3)
        jacobian[:, 3] = self.prediction.tip_per_friction_scale_mm
        return jacobian

    def _tip_model(self, x: np.ndarray) -> np.ndarray:
        p = self.prediction
        return (p.tip_mm + (x[3, 0] - 1.0) * p.tip_per_friction_scale_mm + x[:3, 0]).reshape(-1, 1)

    def _tension_model(self, x: np.ndarray) -> np.ndarray:
        p = self.prediction
        return (p.drive_tension_n + (x[3, 0] - 1.0) * p.tension_per_friction_scale_n).reshape(-1, 1)

    # -- estimates ---------------------------------------------------------------------
    @property
    def tip_mm(self) -> np.ndarray:
        """Estimated tip (3,) [mm]; NaN before the first prediction."""
        if self.prediction is None:
            return np.full(3, np.nan)
        return self._tip_model(self.filter.x).ravel()

    @property
    def tip_covariance_mm2(self) -> np.ndarray:
        """(3, 3) covariance of the tip estimate, H P H^T."""
        if self.prediction is None:
            return np.full((3, 3), np.nan)
        jacobian = self._tip_jacobian()
        return jacobian @ self.filter.P @ jacobian.T

    @property
    def friction_scale(self) -> float:
        return float(self.filter.x[3, 0])
