"""Calibration: fit the Dahl model (and optionally candidate effects) to measured tips.

Least squares over the tip error of every valid sample of the training recordings,

    minimise  sum_t |tip_model(t; p) - tip_measured(t)|^2 + r_scale(p)^2,   p in bounds,

where r_scale is 0 unless the recordings logged drive tensions, and then holds the model tensions'
scale against the logged ones (`tension_scale`: the one direction the tips leave free), with the
model driven by the measured tendon and insertion positions (scipy.optimize.least_squares,
trust-region reflective, forward-difference Jacobian), warm-started from the given parameters.

Between good starting parameters the cost has ridges (where a parameter change flips a tendon
between slack and taut at some moment, or friction holds a bend in one branch and not in the
other), so a fit can stall in a valley. `calibrate_base` fits from several starts
(`model.gap.starting_points`: the prior at a few friction coefficients, and the best points of
a coarse grid by one model run each) and keeps the best end. Which start ends best is not
predictable early: on one clean recording the start best after three cost evaluations ended
at 0.52 mm, another at 0.26 mm.

Uncertainty from the Jacobian J at the solution (in the optimisation variables z):

    cov_z = s^2 (J^T J)^+,   s^2 = |r|^2 / (m - n),

m residuals, n parameters. It assumes independent residuals; tip errors are correlated in time,
so the standard deviations are a lower bound. The correlation matrix shows which parameters
trade off (e.g. EI and mu: friction is proportional to mu * tension and tension to EI).
"""
from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass
from functools import partial

import numpy as np
from scipy.optimize import least_squares

from model.dahl_catheter import ModelSolverError, SolverBudgetExceeded
from model.effects.catalog import combined_terms, effect
from model.gap.free_parameters import ParameterLayout, base_values
from model.gap.recording import Recording
from model.gap.simulation import Resolution, catheter_for, predict_run, solver_work
from model.gap.starting_points import base_grid, base_starts
from model.gap.tension_scale import scale_residual_mm, tension_scale
from model.params import CatheterParams

DIFF_STEP = 0.02       # finite-difference step, DIFF_STEP * max(1, |z|): far above the kernel's ~1 um solver noise
TOLERANCE = 1e-4       # relative change of cost / parameters at which the fit stops
# The friction history makes the cost jump where a parameter change flips a tendon between slack
# and taut at some moment; the trust region then collapses (xtol). A fresh start from the point
# reached usually continues: restart while a run still lowers the cost by RESTART_GAIN.
MAX_RESTARTS = 2
RESTART_GAIN = 0.01
XTOL_REACHED = 3       # least_squares status
DIVERGED_RESIDUAL_MM = 1e3
# Where the solver crawls (e.g. very stiff Dahl friction), a point of a fit is abandoned and scored as
# diverged once its runs along all the recordings together take SLOW_RUN_FACTOR times the solver
# iterations of those at the start (`tip_errors`; and at least
# MIN_ITERATION_LIMIT). Iterations, not time: a time limit made the result depend on the machine's load.
SLOW_RUN_FACTOR = 8.0
MIN_ITERATION_LIMIT = 1000
EXPLORE_ITERATIONS = 3  # cost evaluations of each start's exploratory fit (`explore`)
GRID_STARTS = 3         # the best points of `base_grid` (one model run each) that `calibrate_base` fits from
ZERO_OFFSETS_MM = (0.0, 0.0, 0.0, 0.0)
# Logs are fast when at least FAST_TRAVEL_SHARE of their tendon travel is made at FAST_TENDON_SPEED_MM_S or
# more (the fastest tendon of each sample). Steps make all their travel in jumps (100 %), a 0.6 + 1.7 Hz
# multisine with tendons at up to 9-20 mm/s (issue 16's catheter log) 38 %, the standard excitation 13-21 %.
FAST_TENDON_SPEED_MM_S = 8.0
FAST_TRAVEL_SHARE = 0.3
DYNAMIC_START = (0.02, 1.0)   # damping time [s] and inertia scale a dynamic fit starts from


@dataclass(frozen=True)
class ModelFit:
    """A fitted model: parameters, tendon zero offsets, effect values and their statistics.

    names/values/std: every fitted parameter (physical units, std a lower bound, see module doc);
    correlation: [n, n]; flags: parameters at a fit bound or outside their physical range.
    """

    params: CatheterParams
    zero_offsets_mm: tuple[float, ...]
    effects: dict[str, tuple[float, ...]]
    names: tuple[str, ...] = ()
    values: tuple[float, ...] = ()
    std: tuple[float, ...] = ()
    correlation: tuple[tuple[float, ...], ...] = ()
    flags: tuple[str, ...] = ()
    train_rmse_mm: float = math.nan
    model_runs: int = 0

    def terms(self):
        """The model's EffectTerms with the fitted effects switched on."""
        return combined_terms(self.effects)

    def effect_params(self) -> dict[str, dict[str, float]]:
        """{effect id: {parameter name: value}}."""
        return {effect_id: dict(zip(effect(effect_id).param_names, values))
                for effect_id, values in self.effects.items()}

    def strongest_correlations(self, threshold: float = 0.9) -> list[tuple[str, str, float]]:
        """Pairs of fitted parameters with |correlation| above threshold, strongest first."""
        pairs = [(self.names[i], self.names[j], self.correlation[i][j])
                 for i in range(len(self.names)) for j in range(i + 1, len(self.names))
                 if abs(self.correlation[i][j]) >= threshold]
        return sorted(pairs, key=lambda pair: -abs(pair[2]))

    def as_dict(self) -> dict:
        """Plain JSON-able description: base and effect parameters with std (None where not fitted or
        unidentified), strong correlations, flags, the full catheter."""
        catheter = {name: (list(value) if isinstance(value, tuple) else value)
                    for name, value in vars(self.params).items()}
        known = {name: std for name, std in zip(self.names, self.std) if math.isfinite(std)}
        values = base_values(self.params, self.zero_offsets_mm)
        values.update({f"{effect_id}.{name}": value for effect_id, params in self.effect_params().items()
                       for name, value in params.items()})
        return {"parameters": {name: {"value": value, "std": known.get(name)} for name, value in values.items()},
                "tendon_zero_offsets_mm": list(self.zero_offsets_mm),
                "effects": self.effect_params(),
                "strong_correlations": [{"a": a, "b": b, "correlation": c}
                                        for a, b, c in self.strongest_correlations()],
                "flags": list(self.flags),
                "train_rmse_mm": self.train_rmse_mm,
                "catheter": catheter}

    @classmethod
    def from_dict(cls, data: Mapping) -> "ModelFit":
        """The model part of `as_dict` (catheter, zero offsets, effects) back as a ModelFit."""
        catheter = dict(data["catheter"])
        catheter["tendon_range_mm"] = tuple(catheter["tendon_range_mm"])
        effects = {effect_id: effect(effect_id).values_from(values) for effect_id, values in data["effects"].items()}
        return cls(CatheterParams(**catheter), tuple(data["tendon_zero_offsets_mm"]), effects)


def rmse_mm(errors: Sequence[np.ndarray]) -> float:
    """Root mean square of the Euclidean tip error over all samples of all arrays [n_i, 3]."""
    stacked = np.concatenate([np.asarray(e).reshape(-1, 3) for e in errors])
    return float(np.sqrt(np.mean(np.sum(stacked ** 2, axis=1))))


def tip_errors(fit: ModelFit, recordings: Sequence[Recording], resolution: Resolution,
               iteration_limit: int | None = None) -> list[np.ndarray]:
    """Model minus measured tip [n_valid, 3] per recording (recordings already at the fit resolution).

    Where the model diverges at these parameters, its errors on that recording are infinite.
    iteration_limit bounds the Newton iterations of the runs along all the recordings together
    (what `iteration_limit` measures at a fit's start): once they exceed it, the errors on the
    recording that did and on those after it are infinite. Each recording's run used to get the
    whole limit, so with several recordings the bound was several times SLOW_RUN_FACTOR: on the
    real robot logs (two training recordings) a fit from the prior spent three quarters of its
    Newton iterations in runs that took 10-14x the start's, on parameters (mu at its bound, sigma
    6x the prior) that lowered the training RMSE by 1-2 %.
    """
    return tip_errors_and_tensions(fit, recordings, resolution, iteration_limit)[0]


def tip_errors_and_tensions(fit: ModelFit, recordings: Sequence[Recording], resolution: Resolution,
                            iteration_limit: int | None = None) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """`tip_errors`, and the model's drive tensions [T, 4] per recording (infinite where the run failed)."""
    terms = fit.terms()
    zero = np.asarray(fit.zero_offsets_mm)
    budget = math.inf if iteration_limit is None else iteration_limit
    errors, tensions = [], []
    for r in recordings:
        tips, tension = np.full(r.tip_mm.shape, np.inf), np.full((len(r), 4), np.inf)   # unless the run ends
        if budget >= 0:
            try:
                tips, tension, work = predict_run(fit.params, terms, zero, r, resolution, budget)
                budget -= work
            except SolverBudgetExceeded:
                budget = -1.0
            except ModelSolverError:     # diverged: infinite errors on this recording only
                pass
        error = (tips - r.tip_mm)[r.valid]
        error[~np.isfinite(error)] = np.inf
        errors.append(error)
        tensions.append(tension)
    return errors, tensions


@dataclass
class _Objective:
    """Residual vector r(z): tip_model - tip_measured over every valid sample and, where the recordings
    logged drive tensions, one last entry for the tensions' scale (`tension_scale`). Picklable for workers."""

    layout: ParameterLayout
    start: CatheterParams
    zero_start: np.ndarray
    prepared: list[Recording]
    resolution: Resolution
    iteration_limit: int | None = None

    @property
    def logged_tensions(self) -> bool:
        return any(r.tendon_force_n is not None for r in self.prepared)

    def __call__(self, z: np.ndarray) -> np.ndarray:
        params, zero, values = self.layout.unpack(z, self.start, self.zero_start)
        errors, tensions = tip_errors_and_tensions(ModelFit(params, tuple(zero), values), self.prepared,
                                                   self.resolution, self.iteration_limit)
        out = np.concatenate(errors).ravel()
        if self.logged_tensions:
            logged = [(model, r.tendon_force_n) for model, r in zip(tensions, self.prepared)
                      if r.tendon_force_n is not None]
            scale = tension_scale(*zip(*logged)) if np.all(np.isfinite(out)) else None
            out = np.append(out, scale_residual_mm(scale, len(out) // 3))
        if not np.all(np.isfinite(out)):   # the solver failed at these parameters: make them unattractive
            out = np.full_like(out, DIVERGED_RESIDUAL_MM)
        return out


def calibrate(recordings: Sequence[Recording], start: CatheterParams, *, prior: CatheterParams | None = None,
              zero_offsets_mm: Sequence[float] = ZERO_OFFSETS_MM,
              effects: Mapping[str, Sequence[float]] | None = None, fit_base: bool = True,
              resolution: Resolution = Resolution(), max_iterations: int = 30,
              restarts: int = MAX_RESTARTS, fit_dynamics: bool = False) -> ModelFit:
    """Fit the base parameters (unless fit_base is False) and the given effects' parameters.

    max_iterations bounds the cost evaluations of each least_squares run (not counting the
    Jacobian's); up to `restarts` restarts follow a collapsed trust region.
    recordings: training recordings at full rate (decimated and capped here, Resolution.prepare_training).
    start: warm start; its geometry is replaced by the recordings'. prior: the catheter the
    physical ranges refer to (default: start). effects: {effect id: starting values}.
    fit_dynamics: also fit the damping time and inertia scale (free_parameters.dynamic_parameters).
    Returns a new ModelFit; `start` is unchanged.
    """
    prepared = resolution.prepare_training(recordings)
    start = catheter_for(start, prepared)
    prior = catheter_for(prior or start, prepared)
    effects = {effect_id: tuple(values) for effect_id, values in (effects or {}).items()}
    layout = ParameterLayout(prior, tuple(effects), fit_base, fit_dynamics)
    zero_start = np.asarray(zero_offsets_mm, dtype=float)
    objective = _Objective(layout, start, zero_start, prepared, resolution,
                           iteration_limit(ModelFit(start, tuple(zero_start), effects), prepared, resolution))
    costs: list[float] = []   # 0.5 |r|^2 of every model run, the Jacobian's included

    def residuals(z: np.ndarray) -> np.ndarray:
        out = objective(z)
        costs.append(0.5 * float(out @ out))
        return out

    z = layout.pack(start, zero_start, effects)
    low, high = layout.bounds()
    for _ in range(1 + restarts):
        first_run = len(costs)
        result = least_squares(residuals, z, jac=lambda x: forward_jacobian(objective, residuals, x, low, high),
                               bounds=(low, high), method="trf", ftol=TOLERANCE, xtol=TOLERANCE, gtol=1e-8,
                               max_nfev=max_iterations)
        improved = result.cost < (1.0 - RESTART_GAIN) * costs[first_run]
        z = result.x
        if result.status != XTOL_REACHED or not improved:
            break
    params, zero, values = layout.unpack(result.x, start, zero_start)
    std_z, correlation = _statistics(result.jac, result.fun, len(result.x))
    physical = np.array([p.from_z(z) for p, z in zip(layout.parameters, result.x)])
    std = np.array([p.std(z, s) for p, z, s in zip(layout.parameters, result.x, std_z)])
    flags = layout.flags(physical)
    tip_residuals = result.fun[:len(result.fun) - 1] if objective.logged_tensions else result.fun
    train_rmse = float(np.sqrt(np.sum(tip_residuals ** 2) / max(1, len(tip_residuals) // 3)))
    return ModelFit(params=params, zero_offsets_mm=tuple(float(v) for v in zero), effects=values,
                    names=layout.names, values=tuple(float(v) for v in physical), std=tuple(float(s) for s in std),
                    correlation=tuple(tuple(float(c) for c in row) for row in correlation), flags=flags,
                    train_rmse_mm=train_rmse, model_runs=len(costs))


def forward_jacobian(at: Callable[[np.ndarray], np.ndarray], step: Callable[[np.ndarray], np.ndarray],
                     z: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """Forward differences of the residuals, J[:, i] = (r(z + h_i e_i) - r(z)) / h_i, with

        |h_i| = DIFF_STEP * max(1, |z_i|),   h_i < 0 where z_i + |h_i| would leave the bounds.

    `at` gives r(z) itself (the run least_squares has just made: remembered, not run again), `step`
    each stepped run. scipy's relative step, diff_step * |z_i|, falls back to about 1.5e-8 where
    z_i = 0 exactly: every effect started switched off, every tendon zero started at 0 and every
    log-scaled parameter started at its reference. A step that small is inside the kernel's solver
    noise, and the gradient it gives can point uphill: fitted from twist 0, a torsion of 0.030 rad
    (held-out shrink 0.73 from the true value) stayed at 0."""
    r0 = at(z)
    jacobian = np.empty((len(r0), len(z)))
    for i in range(len(z)):
        h = DIFF_STEP * max(1.0, abs(float(z[i])))
        if z[i] + h > high[i]:
            h = -h
        stepped = z.copy()
        stepped[i] += h
        jacobian[:, i] = (step(stepped) - r0) / h
    return jacobian


def probe_costs(fits: Sequence[ModelFit], recordings: Sequence[Recording], resolution: Resolution) -> list[float]:
    """Training RMSE of each fit (recordings at the fit resolution), one model run each; a run taking
    over SLOW_RUN_FACTOR x the first one's solver iterations is given up (inf)."""
    limit = iteration_limit(fits[0], recordings, resolution)
    return [rmse_mm(tip_errors(fit, recordings, resolution, limit)) for fit in fits]


def iteration_limit(fit: ModelFit, recordings: Sequence[Recording], resolution: Resolution) -> int:
    """SLOW_RUN_FACTOR x the solver iterations of `fit` (a model that runs normally) on the recordings."""
    work = solver_work(fit.params, fit.terms(), np.asarray(fit.zero_offsets_mm), recordings, resolution)
    return max(int(SLOW_RUN_FACTOR * work), MIN_ITERATION_LIMIT)


def explore(recordings: Sequence[Recording], starts: Sequence[ModelFit], prior: CatheterParams,
            resolution: Resolution) -> list[ModelFit]:
    """The short fit (EXPLORE_ITERATIONS cost evaluations, no restarts) of each start, base parameters
    and effects, lowest training RMSE first."""
    explored = [calibrate(recordings, start.params, prior=prior, zero_offsets_mm=start.zero_offsets_mm,
                          effects=start.effects, resolution=resolution, max_iterations=EXPLORE_ITERATIONS, restarts=0)
                for start in starts]
    return sorted(explored, key=lambda fit: fit.train_rmse_mm)


def calibrate_base(recordings: Sequence[Recording], prior: CatheterParams, *, resolution: Resolution = Resolution(),
                   max_iterations: int = 30, executor: Executor | None = None,
                   on_fit: Callable[[int, int], None] | None = None, fit_dynamics: bool = False) -> ModelFit:
    """The base model (no effects) fitted from each of `base_starts(prior)` and the GRID_STARTS best
    points of `base_grid(prior)` (see module doc), each distinct start once: the fit with the lowest
    training RMSE.

    executor: runs the fits in parallel. on_fit(done, total) after each fit.
    fit_dynamics: also fit the damping time and inertia scale (for fast logs, see `is_fast`); the
    starts then begin at a 20 ms damping time and the catheter's own inertia, unless the prior has some.
    """
    prepared = resolution.prepare_training(recordings)
    measured = catheter_for(prior, prepared)     # the recordings' geometry, as `calibrate` gives every start
    grid = [ModelFit(params, ZERO_OFFSETS_MM, {}) for params in base_grid(measured)]
    costs = probe_costs(grid, prepared, resolution)
    starts = base_starts(measured) + [grid[i].params for i in np.argsort(costs, kind="stable")[:GRID_STARTS]]
    starts = [start for i, start in enumerate(starts) if start not in starts[:i]]   # the grid holds the prior
    if fit_dynamics and not prior.dynamic:
        starts = [start.replace(damping_time_s=DYNAMIC_START[0], inertia_scale=DYNAMIC_START[1]) for start in starts]
    fit_from = partial(calibrate, recordings, prior=prior, resolution=resolution, max_iterations=max_iterations,
                       fit_dynamics=fit_dynamics)
    fits = []
    for fit in (executor.map(fit_from, starts) if executor is not None else map(fit_from, starts)):
        fits.append(fit)
        if on_fit is not None:
            on_fit(len(fits), len(starts))
    return min(fits, key=lambda fit: fit.train_rmse_mm)


def fast_travel_share(recordings: Sequence[Recording]) -> float:
    """The share of tendon travel made at FAST_TENDON_SPEED_MM_S or more.

    Per sample, the fastest tendon's travel |du| and speed |du|/dt (finite differences of the logs);
    the share is sum(|du| where fast) / sum(|du|), 0 for logs without motion.
    """
    travel = np.concatenate([np.abs(np.diff(r.tendon_mm, axis=0)).max(axis=1) for r in recordings])
    speed = travel / np.concatenate([np.diff(r.t_s) for r in recordings])
    total = float(travel.sum())
    return float(travel[speed >= FAST_TENDON_SPEED_MM_S].sum()) / total if total > 0 else 0.0


def is_fast(recordings: Sequence[Recording]) -> bool:
    """Whether the logs' inputs are fast enough for the catheter's damping and mass to show (see
    FAST_TRAVEL_SHARE): `crest fit` then fits the dynamic mode's parameters as well."""
    return fast_travel_share(recordings) >= FAST_TRAVEL_SHARE


def _statistics(jac: np.ndarray, fun: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Standard deviations and correlation matrix of z from the Jacobian (see module doc)."""
    m = len(fun)
    dof = max(1, m - n)
    s2 = float(fun @ fun) / dof
    cov = s2 * np.linalg.pinv(jac.T @ jac)
    var = np.diag(cov).copy()
    unidentified = var <= 0
    var[unidentified] = np.inf
    std = np.sqrt(var)
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(std, std)
    corr[~np.isfinite(corr)] = 0.0
    np.fill_diagonal(corr, 1.0)
    return std, np.clip(corr, -1.0, 1.0)
