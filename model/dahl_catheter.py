"""The lumped-parameter catheter with modified Dahl tendon friction (the seed paper's model).

One model serves the predictor, the controller's inverse, the virtual testbed's plant and
the gap diagnosis. The physics is in `model.quasi_static_kernel`; this class holds the
parameters, the state, input validation and the public API.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from model.effect_terms import EffectTerms
from model.params import CatheterParams
from model.quasi_static_kernel import (MAX_NEWTON_ITERATIONS, N_PARAMS, N_SCALARS, P_ALPHA, P_EA, P_EAT, P_EI,
                                       P_FSC, P_INERTIA, P_MU, P_R, P_RHO, P_SIGMA, P_TAU, S_ITERATIONS,
                                       S_UNCONVERGED, run_path)

MIN_ELEMENTS = 4
MAX_DYNAMIC_SAMPLE_S = 10.0   # a longer sample is a hold, not a time step: run() refuses it in the dynamic mode


class ModelInputError(ValueError):
    """A command given to the model is not finite or outside its configured range."""


class ModelSolverError(ArithmeticError):
    """The equilibrium solve produced a non-finite state (parameters far outside their range)."""


class SolverBudgetExceeded(ModelSolverError):
    """A run needed more Newton iterations than its budget (parameters where the solver crawls)."""


@dataclass
class CatheterState:
    """Everything that evolves: applied inputs, friction state, tensions and shape."""

    applied_tendon_mm: np.ndarray   # (4,) tendon input after the drive-train play
    applied_insertion_mm: np.ndarray  # (1,) free length after the tube play
    friction_n: np.ndarray          # (4, N) Dahl force of each tendon/element crossing
    sliding_mm: np.ndarray          # (4, N) tendon sliding past each element, toward the base
    last_step_mm: np.ndarray        # (4, N) sliding increment of the last step (predicts the next)
    tension_n: np.ndarray           # (4, N) mean tendon tension over each element
    last_tension_step_n: np.ndarray  # (4, N) change of that tension in the last step (predicts the next)
    bend_rad: np.ndarray            # (N, 2) element bend vectors
    compression_mm: np.ndarray      # (N,) element axial compression
    tip_tension_n: np.ndarray       # (4,) tension at the tip anchor
    drive_tension_n: np.ndarray     # (4,) tension where the tendon leaves the catheter base
    slack: np.ndarray               # (4,) bool
    points_mm: np.ndarray           # (N+1, 3) backbone
    frames: np.ndarray              # (N+1, 3, 3) element base orientations
    diagnostics: np.ndarray         # (N_SCALARS,) solver counters
    bend_rate_rad_s: np.ndarray     # (N, 2) element bend velocities (dynamic mode; 0 otherwise)
    drive_creep_mm: np.ndarray      # (4,) creep stretch of each drive line (drive_creep effect; 0 otherwise)

    @classmethod
    def straight(cls, n_elements: int, free_length_mm: float) -> "CatheterState":
        n = n_elements
        points = np.zeros((n + 1, 3))
        points[:, 2] = np.linspace(0.0, free_length_mm, n + 1)
        return cls(np.zeros(4), np.array([float(free_length_mm)]), np.zeros((4, n)), np.zeros((4, n)),
                   np.zeros((4, n)), np.zeros((4, n)), np.zeros((4, n)), np.zeros((n, 2)), np.zeros(n), np.zeros(4),
                   np.zeros(4), np.zeros(4, dtype=np.bool_), points, np.tile(np.eye(3), (n + 1, 1, 1)),
                   np.zeros(N_SCALARS), np.zeros((n, 2)), np.zeros(4))

    def copy(self) -> "CatheterState":
        return CatheterState(*[getattr(self, name).copy() for name in _STATE_FIELDS])


_STATE_FIELDS = tuple(f.name for f in dataclasses.fields(CatheterState))


class DahlCatheter:
    """N lumped elements with a Dahl friction element at every tendon/element crossing.

    Inputs: tendon displacements [mm] (positive = pulled) for tendons at 0, 90, 180, 270 deg,
    and the insertion, i.e. the free length [mm] out of the support tube. Outputs are in the
    base frame: origin at the tube exit, z out of the tube, x toward tendon 1.
    The tip is reported as the tracker sees it: p_tip + R_tip d + o, with d =
    `effects.sensor_offset_mm` the sensor's mount offset in the tip frame and o =
    `effects.tracker_offset_mm` the tracker's registration offset in the base frame (0 by default).

    Motion is quasi-static: each input change is followed in sub-steps of at most
    `max_tendon_step_mm` of tendon and `max_insertion_step_mm` of insertion, so the friction
    history follows the path; a sub-step whose Newton solve needs more than
    `max_newton_iterations` is retried in halves.

    Dynamic mode (params.dynamic: a damping time or an inertia scale > 0, seed paper I.A): `run`
    integrates the element bends in time, M b'' + C b' + K b = tendon, friction and external
    moments, by backward Euler (implicit, L-stable) in steps of at most `max_time_step_s`;
    `move_to` is a move to rest (the quasi-static limit). Math: quasi_static_kernel.dynamic_bend_offset.
    The default 10 ms is one step per sample at 100 Hz. With a 20 ms damping time and the catheter's
    own mass, its tip follows a 1.25 ms reference within 0.04 mm RMS (0.13 mm at most) on a
    multisine pulling at up to 18 mm/s and on a 120 deg step; 5 ms steps gave 0.025 mm RMS at twice
    the cost (tests/model/test_dynamics.py::test_ten_ms_steps_follow_a_fine_time_step).
    """

    def __init__(self, params: CatheterParams, n_elements: int = 20, effects: EffectTerms = EffectTerms(),
                 max_tendon_step_mm: float = 0.05, max_insertion_step_mm: float = 0.5,
                 max_newton_iterations: int = MAX_NEWTON_ITERATIONS, max_time_step_s: float = 0.01):
        if isinstance(n_elements, bool) or not isinstance(n_elements, (int, np.integer)) \
                or n_elements < MIN_ELEMENTS:
            raise ValueError(f"n_elements must be an integer >= {MIN_ELEMENTS}, got {n_elements!r}")
        if not (max_tendon_step_mm > 0 and max_insertion_step_mm > 0):
            raise ValueError("max_tendon_step_mm and max_insertion_step_mm must be > 0")
        if not 0 < max_time_step_s < math.inf:
            raise ValueError(f"max_time_step_s must be a finite time > 0 s, got {max_time_step_s!r}")
        if not max_newton_iterations >= 1:
            raise ValueError(f"max_newton_iterations must be >= 1, got {max_newton_iterations!r}")
        self.params = params
        self.n_elements = int(n_elements)
        self.effects = effects
        self.max_tendon_step_mm = float(max_tendon_step_mm)
        self.max_insertion_step_mm = float(max_insertion_step_mm)
        self.max_newton_iterations = int(max_newton_iterations)
        self.max_time_step_s = float(max_time_step_s)
        self._kernel_params = self._pack(params)
        self._kernel_effects = effects.kernel_vector()
        self._sensor_offset_mm = np.asarray(effects.sensor_offset_mm, dtype=float)
        self._tracker_offset_mm = np.asarray(effects.tracker_offset_mm, dtype=float)
        self._point_loads = np.empty((0, 4))     # (fx, fy, fz [N], distance from the tip [mm])
        self.reset()

    @staticmethod
    def _pack(p: CatheterParams) -> np.ndarray:
        v = np.empty(N_PARAMS)
        v[P_R] = p.tendon_offset_mm
        v[P_EI] = p.bending_stiffness_nmm2
        v[P_EA] = p.axial_stiffness_n
        v[P_EAT] = p.tendon_stiffness_n
        v[P_MU] = p.mu
        v[P_FSC] = p.fsc_n_per_mm
        v[P_SIGMA] = p.sigma_n_per_mm2
        v[P_ALPHA] = p.alpha
        v[P_RHO] = p.linear_density_kg_per_mm
        v[P_TAU] = p.damping_time_s
        v[P_INERTIA] = p.inertia_scale
        return v

    # -- state -------------------------------------------------------------------------
    def reset(self) -> None:
        """Straight, unloaded, at the parameters' free length, with zero friction state."""
        self.state = CatheterState.straight(self.n_elements, self.params.free_length_mm)

    def snapshot(self) -> CatheterState:
        """A copy of the state, to restore later with `restore` (e.g. for prediction)."""
        return self.state.copy()

    def restore(self, state: CatheterState) -> None:
        self.state = state.copy()

    # -- external loads ----------------------------------------------------------------
    def set_point_forces(self, forces_n, from_tip_mm=None) -> None:
        """External point forces on the catheter, from the next move on (replacing earlier ones).

        forces_n (K, 3) in N in the base frame; from_tip_mm (K,) their distance from the tip along
        the backbone [mm] (default 0: at the tip), so a contact stays where it is on the catheter
        when the insertion changes. A force whose point is inside the support tube acts on the tube.
        The forces bend each element through the contact-point Jacobian (seed paper II). They act
        on the shape of the previous sub-step, so after a large change of load call move_to again
        until the tip settles. `set_point_forces(np.empty((0, 3)))` removes them.
        """
        forces = np.asarray(forces_n, dtype=float).reshape(-1, 3)
        distances = np.zeros(len(forces)) if from_tip_mm is None else np.asarray(from_tip_mm, float).reshape(-1)
        if distances.shape != (len(forces),):
            raise ModelInputError(f"from_tip_mm must hold one distance per force ({len(forces)}), "
                                  f"got shape {distances.shape}")
        if not (np.isfinite(forces).all() and np.isfinite(distances).all()):
            raise ModelInputError("point forces and their distances from the tip must be finite")
        if (distances < 0).any():
            raise ModelInputError(f"distances from the tip must be >= 0 mm, got {distances.min():g}")
        self._point_loads = np.ascontiguousarray(np.column_stack([forces, distances]))

    @property
    def point_forces_n(self) -> np.ndarray:
        """(K, 3) external point forces now acting [N], base frame."""
        return self._point_loads[:, :3].copy()

    # -- motion ------------------------------------------------------------------------
    def move_to(self, tendons_mm, insertion_mm: float | None = None) -> np.ndarray:
        """Drive quasi-statically from the current state to this input; returns the tip [mm].

        History carries over: the friction state evolves along the straight-line input path.
        In the dynamic mode this is a move slow enough to end at rest (the quasi-static limit).
        """
        if insertion_mm is None:
            insertion_mm = float(self.state.applied_insertion_mm[0])
        tendons, insertion = self._validated(np.asarray(tendons_mm, dtype=float).reshape(1, -1),
                                             np.asarray([insertion_mm], dtype=float).reshape(-1))
        return self._run(tendons, insertion, np.inf)[0][0]

    def run(self, tendons_mm, insertion_mm=None, dt_s: float = 0.01,
            max_solver_iterations: float = math.inf) -> np.ndarray:
        """Drive along a sampled input path tendons_mm[T, 4], insertion_mm[T]; tips [T, 3] in mm.

        dt_s is the sample period [s]; it matters for rate-dependent effects and, in the dynamic
        mode, is the time each sample takes (then it must be finite: at most 10 s).
        max_solver_iterations: SolverBudgetExceeded (state unchanged) as soon as the run has taken
        more Newton iterations; a measure of work that, unlike time, does not depend on the machine.
        """
        return self.run_with_tension(tendons_mm, insertion_mm, dt_s, max_solver_iterations)[0]

    def run_with_tension(self, tendons_mm, insertion_mm=None, dt_s: float = 0.01,
                         max_solver_iterations: float = math.inf) -> tuple[np.ndarray, np.ndarray]:
        """`run`, and the tendon tensions at the drives after each sample [T, 4] in N (what the drives log)."""
        tendons = np.asarray(tendons_mm, dtype=float)
        if insertion_mm is None:
            insertion_mm = np.full(len(tendons), float(self.state.applied_insertion_mm[0]))
        tendons, insertion = self._validated(tendons, np.asarray(insertion_mm, dtype=float))
        if not (dt_s > 0):
            raise ModelInputError(f"dt_s must be > 0, got {dt_s!r}")
        if self.params.dynamic and not dt_s <= MAX_DYNAMIC_SAMPLE_S:
            raise ModelInputError(f"dt_s = {dt_s!r} s: the dynamic mode integrates in time and needs a finite "
                                  f"sample period of at most {MAX_DYNAMIC_SAMPLE_S:g} s (use move_to for a move "
                                  "to rest)")
        return self._run(tendons, insertion, float(dt_s), float(max_solver_iterations))

    def _run(self, tendons: np.ndarray, insertion: np.ndarray, dt_s: float,
             max_solver_iterations: float = math.inf) -> tuple[np.ndarray, np.ndarray]:
        before = self.state.copy()
        s = self.state
        tips = np.empty((len(tendons), 3))
        tension = np.empty((len(tendons), 4))
        done = run_path(tendons, insertion, dt_s, self.max_tendon_step_mm, self.max_insertion_step_mm,
                        self.max_newton_iterations, max_solver_iterations, self._kernel_params,
                        self._kernel_effects, self._point_loads, s.applied_tendon_mm, s.applied_insertion_mm,
                        s.friction_n, s.sliding_mm, s.last_step_mm, s.tension_n, s.last_tension_step_n,
                        s.bend_rad, s.compression_mm, s.tip_tension_n, s.drive_tension_n, s.slack, s.points_mm,
                        s.frames, s.diagnostics, tips, tension,
                        self.max_time_step_s, s.bend_rate_rad_s, s.drive_creep_mm)
        if done < len(tendons):
            self.state = before
            raise SolverBudgetExceeded(f"the model run stopped at sample {done} of {len(tendons)}: over its budget "
                                       f"of {max_solver_iterations:g} solver iterations; the state is unchanged")
        if not (np.isfinite(tips).all() and np.isfinite(s.friction_n).all()):
            self.state = before
            raise ModelSolverError(f"the catheter model diverged (non-finite state) with {self.params}; "
                                   "the state is unchanged. Check the parameters' ranges.")
        return tips, tension

    def _validated(self, tendons: np.ndarray, insertion: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Check shapes, finiteness and ranges before anything touches the state."""
        if tendons.ndim != 2 or tendons.shape[1] != 4:
            raise ModelInputError(f"tendon commands must have shape (T, 4), got {tendons.shape}")
        if insertion.shape != (tendons.shape[0],):
            raise ModelInputError(f"insertion must have shape ({tendons.shape[0]},), got {insertion.shape}")
        low, high = self.params.tendon_range_mm
        lo, hi = self.params.min_free_length_mm, self.params.max_free_length_mm
        # one pass for the common case: a range check fails for NaN and inf as well
        if ((tendons >= low) & (tendons <= high)).all() and ((insertion >= lo) & (insertion <= hi)).all():
            return np.ascontiguousarray(tendons), np.ascontiguousarray(insertion)
        bad = ~np.isfinite(tendons)
        if bad.any():
            t, k = np.argwhere(bad)[0]
            raise ModelInputError(f"tendon {k + 1} command at sample {t} is {tendons[t, k]}: must be finite")
        if not np.isfinite(insertion).all():
            t = int(np.argwhere(~np.isfinite(insertion))[0, 0])
            raise ModelInputError(f"insertion at sample {t} is {insertion[t]}: must be finite")
        outside = (tendons < low) | (tendons > high)
        if outside.any():
            t, k = np.argwhere(outside)[0]
            raise ModelInputError(f"tendon {k + 1} command {tendons[t, k]:.3f} mm at sample {t} is outside "
                                  f"the configured range [{low}, {high}] mm")
        outside = (insertion < lo) | (insertion > hi)
        if outside.any():
            t = int(np.argwhere(outside)[0, 0])
            raise ModelInputError(f"free length {insertion[t]:.3f} mm at sample {t} is outside "
                                  f"[{lo}, {hi}] mm (it cannot be negative or beyond the catheter)")
        raise ModelInputError("tendon or insertion command outside its range")

    # -- outputs -----------------------------------------------------------------------
    @property
    def tip_mm(self) -> np.ndarray:
        return self.state.points_mm[-1] + self.state.frames[-1] @ self._sensor_offset_mm + self._tracker_offset_mm

    @property
    def backbone_mm(self) -> np.ndarray:
        """(N+1, 3) element end points from the tube exit to the tip."""
        return self.state.points_mm.copy()

    @property
    def tendon_tension_n(self) -> np.ndarray:
        """(4, N) mean tension of each tendon over each element."""
        return self.state.tension_n.copy()

    @property
    def drive_tension_n(self) -> np.ndarray:
        """(4,) tension of each tendon at the catheter base (what the drive pulls against)."""
        return self.state.drive_tension_n.copy()

    @property
    def curvature_per_mm(self) -> np.ndarray:
        """(N,) curvature of each element: |b_i| / h."""
        h = self.free_length_mm / self.n_elements
        return np.hypot(self.state.bend_rad[:, 0], self.state.bend_rad[:, 1]) / h

    @property
    def free_length_mm(self) -> float:
        return float(self.state.applied_insertion_mm[0])

    @property
    def solver_iterations(self) -> tuple[int, int]:
        """(Newton iterations in total, steps that hit the iteration limit) since reset."""
        return int(self.state.diagnostics[S_ITERATIONS]), int(self.state.diagnostics[S_UNCONVERGED])
