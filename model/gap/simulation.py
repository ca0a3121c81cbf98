"""Drive the one Dahl model along recordings: the prediction every fit and comparison uses.

The model input is u_model,k = u_measured,k - zero_k: the tendon zero offsets are where the
drive's zero lies relative to the tendon's just-taut position. Each recording starts from the
straight, unloaded state at its first free length.
"""
from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from model.dahl_catheter import DahlCatheter, ModelSolverError, SolverBudgetExceeded
from model.effect_terms import EffectTerms
from model.gap.free_parameters import TENDON_OFFSET_FIT_SPAN
from model.gap.recording import Recording, RecordingError
from model.params import CatheterParams

TENDON_RANGE_MARGIN_MM = 10.0


@dataclass(frozen=True)
class Resolution:
    """How finely the diagnosis simulates: coarser than a plant, fine enough not to change the answer.

    n_elements: lumped elements (the plant uses 20; 8 moves the tip by < 0.05 mm RMS on the
        standard excitation, well below tracker noise).
    max_tendon_step_mm, max_insertion_step_mm: quasi-static sub-step sizes (plant: 0.05, 0.5).
        At 10 Hz, 0.5 mm tendon steps reproduce the plant as well as 0.25 mm (tip RMSE 0.04-0.2 mm
        at the plant's own parameters) and run faster; with rate friction the kernel's result
        depends on the sub-step length (0.25 mm was worse on some plants). Insertion steps of 2 mm
        at 8 elements made the kernel return NaN on some paths.
    max_newton_iterations: at these coarse sub-steps a solve that needs many Newton iterations
        at a tendon's reversal or slack/taut switch can end on a spurious equilibrium; retried in
        halves it follows the plant. With the default 12, a 1e-9 relative change of EI changed
        one held-out RMSE from 0.25 to 0.33 mm (a 3 mm tip jump for a few samples) and a
        switched-off effect (1e-9) to 0.64 mm; with 8, all stayed at 0.25 mm. Since the kernel
        locates where a slack tendon tightens (quasi_static_kernel.run_path), the cap no longer
        decides that either: caps 8 and 12 follow the same branch (tests/model/test_tightening.py).
    fit_rate_hz: recordings are decimated to about this rate for fitting and evaluation; the
        smooth excitation loses nothing at 10 Hz.
    max_fit_samples: fits use at most this many (decimated) training samples in total, each
        recording cut to its first part in proportion: a run costs about 10 us per sample and
        sub-step, and the standard training excitation (about 230 s, 2300 samples) holds every
        primitive, so a longer log repeats what the fit has already seen. Held-out recordings
        are decimated like the training ones but never cut. `sampling` says what a diagnosis used.
    """

    n_elements: int = 8
    max_tendon_step_mm: float = 0.5
    max_insertion_step_mm: float = 0.5
    max_newton_iterations: int = 8
    fit_rate_hz: float = 10.0
    max_fit_samples: int = 2400

    def decimation(self, recording: Recording) -> int:
        """The decimation factor that brings this recording to about `fit_rate_hz`."""
        return max(1, int(round(1.0 / (recording.sample_period_s * self.fit_rate_hz))))

    def prepare(self, recordings: Sequence[Recording]) -> list[Recording]:
        """Recordings decimated to about `fit_rate_hz` (for evaluation)."""
        return [r.decimated(self.decimation(r)) for r in recordings]

    def prepare_training(self, recordings: Sequence[Recording]) -> list[Recording]:
        """Decimated, and cut so that the total is at most `max_fit_samples` (for fitting)."""
        decimated = self.prepare(recordings)
        total = sum(len(r) for r in decimated)
        if total <= self.max_fit_samples:
            return decimated
        return [r.head(max(3, self.max_fit_samples * len(r) // total)) for r in decimated]

    def sampling(self, train: Sequence[Recording], holdout: Sequence[Recording]) -> dict:
        """What of the logs the diagnosis uses: per recording, its rows (and rows with a tip), the
        decimation factor, and the rows the fits use (training, after decimation and the
        `max_fit_samples` cap) or the held-out evaluation uses (decimated, never capped); with the
        time span used and whether the fits saw only the head of the training logs (`capped`).

        A decimated row stands for its block of `decimation` rows (`Recording.decimated`); the rows
        between are not compared, so the held-out error is the error on every `decimation`-th row.
        """
        def rows(recording: Recording, used: Recording, decimation: int) -> dict:
            return {"recording": recording.name, "rows": len(recording), "rows_with_tip": int(recording.valid.sum()),
                    "decimation": decimation, "rows_used": len(used), "rows_used_with_tip": int(used.valid.sum()),
                    "duration_s": float(recording.t_s[-1] - recording.t_s[0]),
                    "duration_used_s": float(used.t_s[-1] - used.t_s[0])}

        fitted = self.prepare_training(train)
        train_rows = [rows(r, used, self.decimation(r)) for r, used in zip(train, fitted)]
        holdout_rows = [rows(r, used, self.decimation(r)) for r, used in zip(holdout, self.prepare(holdout))]
        decimated_rows = sum(len(r) for r in self.prepare(train))
        return {"fit_rate_hz": self.fit_rate_hz, "max_fit_samples": self.max_fit_samples,
                "capped": decimated_rows > self.max_fit_samples,
                "decimated": any(row["decimation"] > 1 for row in train_rows + holdout_rows),
                "train_rows": sum(row["rows"] for row in train_rows),
                "train_rows_used": sum(row["rows_used"] for row in train_rows),
                "holdout_rows": sum(row["rows"] for row in holdout_rows),
                "holdout_rows_used": sum(row["rows_used"] for row in holdout_rows),
                "train": train_rows, "holdout": holdout_rows}


def catheter_for(base: CatheterParams, recordings: Sequence[Recording]) -> CatheterParams:
    """`base` with the geometry of the recordings (which must agree) and ranges that admit their inputs.

    Outer diameter and maximum free length come from the recordings; the free length at reset is
    set per recording by `predict_tips`. The tendon offset is the recordings' nominal one, unless
    `base` has one within the fit's span of it (TENDON_OFFSET_FIT_SPAN): a fitted offset, kept.
    """
    first = recordings[0]
    for r in recordings[1:]:
        if not (np.isclose(r.tendon_offset_mm, first.tendon_offset_mm)
                and np.isclose(r.flexible_length_mm, first.flexible_length_mm)):
            raise RecordingError(f"{r.name}: catheter geometry (tendon offset {r.tendon_offset_mm} mm, flexible "
                                 f"length {r.flexible_length_mm} mm) differs from {first.name} "
                                 f"({first.tendon_offset_mm} mm, {first.flexible_length_mm} mm); "
                                 "analyse logs of one catheter together")
    offset = first.tendon_offset_mm
    if abs(base.tendon_offset_mm / offset - 1.0) <= TENDON_OFFSET_FIT_SPAN:
        offset = base.tendon_offset_mm
    diameter = first.outer_diameter_mm
    if diameter is None:
        diameter = max(base.outer_diameter_mm, 2.2 * offset)
    insertion = np.concatenate([r.insertion_mm for r in recordings])
    reach = max(float(np.max(np.abs(r.tendon_mm))) for r in recordings) + TENDON_RANGE_MARGIN_MM
    longest = max(first.flexible_length_mm, float(insertion.max()))
    shortest = min(base.min_free_length_mm, 0.5 * float(insertion.min()))
    return base.replace(tendon_offset_mm=offset, outer_diameter_mm=float(diameter), max_free_length_mm=longest,
                        min_free_length_mm=shortest, free_length_mm=float(np.clip(base.free_length_mm, shortest,
                                                                                     longest)),
                        tendon_range_mm=(-reach, reach))


def predict_tips(params: CatheterParams, effects: EffectTerms, zero_offsets_mm: np.ndarray, recording: Recording,
                 resolution: Resolution, iteration_limit: int | None = None) -> np.ndarray:
    """Model tips [T, 3] (mm) along the recording's measured inputs, from the straight state.

    With an iteration limit (Newton iterations of the quasi-static solver: a measure of the work
    that, unlike a time, does not depend on the machine or what else it runs, so a fit's result
    does not either) the run stops as soon as it exceeds the limit, with SolverBudgetExceeded
    (fits use it to give up on parameters that make the solver crawl).
    """
    return _run(params, effects, zero_offsets_mm, recording, resolution, iteration_limit)[0]


def predict_tips_and_tension(params: CatheterParams, effects: EffectTerms, zero_offsets_mm: np.ndarray,
                             recording: Recording, resolution: Resolution) -> tuple[np.ndarray, np.ndarray]:
    """Model tips [T, 3] (mm) and drive tensions [T, 4] (N) after each sample."""
    return _run(params, effects, zero_offsets_mm, recording, resolution)[:2]


def predict_run(params: CatheterParams, effects: EffectTerms, zero_offsets_mm: np.ndarray, recording: Recording,
                resolution: Resolution, iteration_limit: int | None = None) -> tuple[np.ndarray, np.ndarray, int]:
    """`predict_tips_and_tension` and the Newton iterations the run took (the unit of its limit)."""
    return _run(params, effects, zero_offsets_mm, recording, resolution, iteration_limit)


def solver_work(params: CatheterParams, effects: EffectTerms, zero_offsets_mm: np.ndarray,
                recordings: Sequence[Recording], resolution: Resolution) -> int:
    """Newton iterations of the model's runs along the recordings (the unit of `predict_tips`' limit)."""
    return sum(_run(params, effects, zero_offsets_mm, r, resolution)[2] for r in recordings)


def _run(params: CatheterParams, effects: EffectTerms, zero_offsets_mm: np.ndarray, recording: Recording,
         resolution: Resolution, iteration_limit: int | None = None) -> tuple[np.ndarray, np.ndarray, int]:
    """Tips [T, 3], drive tensions [T, 4] and the Newton iterations they took (see `predict_tips`).

    The latest runs of this process (up to RUN_MEMORY_BYTES) are remembered by their exact inputs
    (parameters and effects by repr, which tells -0.0 from 0.0; zero offsets and the recording's
    inputs by their bytes). A fit asks for the same run again where it continues from a point it has fitted before:
    a restart or a final fit re-evaluates the cost and the finite-difference Jacobian at the point
    the previous least-squares run ended on, and every fit first measures the solver work of its
    start (`calibration.iteration_limit`) and then evaluates the cost there. The model is
    deterministic, so a remembered run is the run: it fails again where its Newton iterations exceed
    the limit now asked for. A run given up at a limit fails under any limit up to that one and
    runs again under a higher one; a diverged run diverges again (both are ModelSolverErrors, which
    the fits score alike).
    """
    key = (repr(params), repr(effects), np.asarray(zero_offsets_mm, dtype=float).tobytes(), recording.input_digest,
           resolution)
    limit = math.inf if iteration_limit is None else iteration_limit
    known = _RUNS.get(key)
    if known is not None:
        if known.diverged:
            raise ModelSolverError(f"the catheter model diverged (non-finite state) with {params}")
        if known.tips is not None and known.iterations <= limit:
            return known.tips.copy(), known.tension.copy(), known.iterations
        if known.tips is not None or limit <= known.iterations:
            raise SolverBudgetExceeded(f"the model run takes over {limit:g} solver iterations, its budget")
    model = _model(params, effects, recording, resolution)
    try:
        tips, tension = model.run_with_tension(recording.tendon_mm - zero_offsets_mm, recording.insertion_mm,
                                               recording.sample_period_s, limit)
    except SolverBudgetExceeded:
        _RUNS.remember(key, _Outcome(None, None, limit, False))
        raise
    except ModelSolverError:
        _RUNS.remember(key, _Outcome(None, None, 0, True))
        raise
    _RUNS.remember(key, _Outcome(tips.copy(), tension.copy(), model.solver_iterations[0], False))
    return tips, tension, model.solver_iterations[0]


# Runs remembered per process, by the bytes of their tips and tensions (7 numbers a sample: about 27 kB a
# run of a test's training log, 53 kB of the blind benchmark's). A fit's restarts and final fits return
# to points fitted a few hundred runs before: a test diagnosis (`tests.gap.conftest`, backlash, one
# worker) made 4796 model runs with the 96 runs remembered until 2026-12-07, 4410 with 64 MB, and gave
# the same result.
RUN_MEMORY_BYTES = 64 * 2 ** 20


@dataclass(frozen=True)
class _Outcome:
    """A remembered run: its tips, drive tensions and Newton iterations; or no tips, over a budget of
    `iterations`; or diverged."""

    tips: np.ndarray | None
    tension: np.ndarray | None
    iterations: float
    diverged: bool


class _RunMemory:
    """The remembered runs, least recently used first, within RUN_MEMORY_BYTES (a run's tips and
    tensions, and KEY_BYTES for its key, so that failed runs count too)."""

    KEY_BYTES = 1024

    def __init__(self):
        self.runs: OrderedDict[tuple, _Outcome] = OrderedDict()
        self.nbytes = 0

    def get(self, key: tuple) -> _Outcome | None:
        known = self.runs.get(key)
        if known is not None:
            self.runs.move_to_end(key)
        return known

    def remember(self, key: tuple, outcome: _Outcome) -> None:
        old = self.runs.pop(key, None)
        self.nbytes += self._size(outcome) - (self._size(old) if old else 0)
        self.runs[key] = outcome
        while self.nbytes > RUN_MEMORY_BYTES and len(self.runs) > 1:
            self.nbytes -= self._size(self.runs.popitem(last=False)[1])

    def _size(self, outcome: _Outcome) -> int:
        arrays = 0 if outcome.tips is None else outcome.tips.nbytes + outcome.tension.nbytes
        return self.KEY_BYTES + arrays


_RUNS = _RunMemory()


def _model(params: CatheterParams, effects: EffectTerms, recording: Recording,
           resolution: Resolution) -> DahlCatheter:
    start = params.replace(free_length_mm=float(np.clip(recording.insertion_mm[0], params.min_free_length_mm,
                                                        params.max_free_length_mm)))
    return DahlCatheter(start, n_elements=resolution.n_elements, effects=effects,
                        max_tendon_step_mm=resolution.max_tendon_step_mm,
                        max_insertion_step_mm=resolution.max_insertion_step_mm,
                        max_newton_iterations=resolution.max_newton_iterations)
