"""Invert the Dahl catheter model online: the command the model predicts puts the tip on a target.

Unknowns x = (p_x, p_y, L): the differential pulls of the pairs 1/3 and 2/4 [mm] (pretension
u0 kept: u = (u0 + p_x, u0 + p_y, u0 - p_x, u0 - p_y)) and the free length L [mm]. From the
model's current state S (its friction history), f(x) is the tip after model.move_to(u(x), L).
Each call minimises

    J(x) = |tip* - f(x)|^2 + w_L (L - L_ref)^2,      lower <= x <= upper

by damped Gauss-Newton (Levenberg-Marquardt), with A ~ df/dx and W = diag(0, 0, w_L):

    (A^T A + W + lambda I) dx = A^T (tip* - f(x)) - W (x - x_ref),   x <- clip(x + dx)

A is carried over from the previous call (warm start) and refined after every trial step by
Broyden's secant update A <- A + ((df - A dx) dx^T) / (dx^T dx); it is rebuilt by forward
differences when a step from a carried-over A fails to lower J. Each trial starts from S, so
the slope includes the friction state: right after a reversal the tip barely follows the
tendons, and the solve pulls further to cross the friction band.

The free length is an unknown because a catheter whose curvature is not constant (friction
consumes tension toward the tip) cannot put its tip on an arbitrary point at a fixed length:
at 180 deg the pulls alone leave ~3 mm. The small w_L only keeps L near the set-point where
the pulls suffice. The model's state is restored after every trial: solving commits nothing.
A call costs at most max_evaluations model moves; it stops early at the tolerance, or when an
accepted step lowers J by less than MIN_PROGRESS.

The inverse stays quasi-static when the model is in its dynamic mode (CatheterParams [dynamics]):
move_to is then a move to rest, so the solve finds the command whose settled tip is on the target,
and the commanded model advances in time between calls. The dynamic lag it leaves is small at the
commanded speeds (measured on the default catheter, 20 elements, 100 Hz, 30-90/120 deg cosine
articulations, tip distance dynamic - quasi-static after the start-up second, 95th percentile):
tau = 20 ms (inertia 1): 0.06 mm at 2 mm/s of tendon, 0.12 at 4, 0.24 at 8, 0.49 at 18 mm/s;
tau = 50 ms: 0.15, 0.35, 0.78, 1.5 mm. Up to the slow excitation's speeds (<= 4 mm/s) that is at
the tracker's noise; compensating the lag would need one dynamic run per trial step (a full SYNC
period each), which the 12-evaluation budget per cycle does not allow at 100 Hz.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from model import DahlCatheter

from control.inverse_kinematics import tendons_from_pulls

MIN_PROGRESS = 0.01   # an accepted step must lower J by this fraction, or the solve stops


@dataclass(frozen=True)
class InverseSolution:
    """x: (p_x, p_y, L) [mm]; tip_mm: the model's tip there; residual_mm: |tip* - tip_mm|;
    evaluations: model moves spent; limited: a bound kept the solution off the target."""

    x: np.ndarray
    tip_mm: np.ndarray
    residual_mm: float
    evaluations: int
    limited: bool


class DahlInverse:
    """Solves for x on `model` from its current state; call `reset` when the model is reset."""

    def __init__(self, model: DahlCatheter, pretension_mm: float, *, insertion_weight: float = 1e-3,
                 tolerance_mm: float = 0.03, max_evaluations: int = 12,
                 difference_steps_mm: tuple[float, float, float] = (0.02, 0.02, 0.1), damping: float = 1e-4):
        self.model = model
        self.pretension_mm = float(pretension_mm)
        self.weights = np.diag([0.0, 0.0, float(insertion_weight)])
        self.tolerance_mm = float(tolerance_mm)
        self.max_evaluations = int(max_evaluations)
        self.difference_steps_mm = np.asarray(difference_steps_mm, dtype=float)
        self.damping = float(damping)
        self._jacobian: np.ndarray | None = None

    def reset(self) -> None:
        self._jacobian = None

    def solve(self, target_tip_mm, x0, insertion_ref_mm: float, lower, upper) -> InverseSolution:
        target = np.asarray(target_tip_mm, dtype=float)
        lower = np.asarray(lower, dtype=float)
        upper = np.asarray(upper, dtype=float)
        x_ref = np.array([0.0, 0.0, float(insertion_ref_mm)])
        start = self.model.snapshot()
        x = np.clip(np.asarray(x0, dtype=float), lower, upper)
        tip = self._tip(start, x)
        evaluations = 1
        cost = self._cost(target, tip, x, x_ref)
        jacobian = self._jacobian
        fresh = jacobian is None
        if fresh:
            jacobian = self._finite_differences(start, x, tip, upper)
            evaluations += 3
        damping = self.damping
        while evaluations < self.max_evaluations and np.linalg.norm(target - tip) > self.tolerance_mm:
            normal = jacobian.T @ jacobian + self.weights + damping * np.eye(3)
            gradient = jacobian.T @ (target - tip) - self.weights @ (x - x_ref)
            trial = np.clip(x + np.linalg.solve(normal, gradient), lower, upper)
            step = trial - x
            if step @ step < 1e-14:
                break   # converged onto a bound (or a stationary point)
            trial_tip = self._tip(start, trial)
            evaluations += 1
            jacobian = jacobian + np.outer(trial_tip - tip - jacobian @ step, step) / (step @ step)
            trial_cost = self._cost(target, trial_tip, trial, x_ref)
            if trial_cost < cost:
                stalled = trial_cost > (1.0 - MIN_PROGRESS) * cost
                x, tip, cost, fresh = trial, trial_tip, trial_cost, False
                damping = max(damping / 3.0, self.damping)
                if stalled:
                    break   # held by a bound or a kink of the friction law: more trials buy nothing
            elif not fresh and evaluations + 3 <= self.max_evaluations:
                jacobian = self._finite_differences(start, x, tip, upper)
                evaluations += 3
                fresh = True
            else:
                damping *= 10.0
        self._jacobian = jacobian
        self.model.restore(start)
        residual = float(np.linalg.norm(target - tip))
        at_bound = bool(np.any((x <= lower + 1e-9) | (x >= upper - 1e-9)))
        return InverseSolution(x, tip, residual, evaluations, at_bound and residual > self.tolerance_mm)

    def _tip(self, start, x: np.ndarray) -> np.ndarray:
        self.model.restore(start)
        return self.model.move_to(tendons_from_pulls(x[:2], self.pretension_mm), x[2])

    def _cost(self, target: np.ndarray, tip: np.ndarray, x: np.ndarray, x_ref: np.ndarray) -> float:
        error = target - tip
        offset = x - x_ref
        return float(error @ error + offset @ self.weights @ offset)

    def _finite_differences(self, start, x: np.ndarray, tip: np.ndarray, upper: np.ndarray) -> np.ndarray:
        """Forward differences df/dx_j (stepping down where a step up would leave the box)."""
        jacobian = np.empty((3, 3))
        for j in range(3):
            step = self.difference_steps_mm[j] if x[j] + self.difference_steps_mm[j] <= upper[j] \
                else -self.difference_steps_mm[j]
            shifted = x.copy()
            shifted[j] += step
            jacobian[:, j] = (self._tip(start, shifted) - tip) / step
        return jacobian
