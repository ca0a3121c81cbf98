"""A fit gives up on parameters where the solver crawls by counting Newton iterations (issue 17): the
limit bounds the runs along all the recordings together, not each recording's run, and a remembered
run obeys the limit it is asked for like a fresh one. The remembered runs stay within their bytes."""
import math

import numpy as np
import pytest

from model import CatheterParams, SolverBudgetExceeded
from model.gap.calibration import MIN_ITERATION_LIMIT, ModelFit, tip_errors
from model.gap.candidates import holdout_iteration_limit
from model.gap.recording import Recording
from model.gap import simulation
from model.gap.simulation import Resolution, catheter_for, predict_run

RESOLUTION = Resolution(n_elements=6)


def bending_recording(name: str, turns: float) -> Recording:
    """A 10 Hz log of tendon 1 and 3 pulled antagonistically back and forth (4 mm amplitude)."""
    t_s = np.arange(0.0, 20.0 * turns, 0.1)
    pull_mm = 4.0 * np.sin(2 * math.pi * t_s / 20.0)
    tendon_mm = np.column_stack([pull_mm, np.zeros_like(t_s), -pull_mm, np.zeros_like(t_s)])
    return Recording(name, t_s, tendon_mm, np.full(len(t_s), 80.0), np.zeros((len(t_s), 3)), None,
                     flexible_length_mm=80.0, tendon_offset_mm=1.0, outer_diameter_mm=None)


@pytest.fixture(scope="module")
def case():
    recordings = [bending_recording("first", 1.0), bending_recording("second", 1.5)]
    fit = ModelFit(catheter_for(CatheterParams.from_toml(), recordings), (0.0, 0.0, 0.0, 0.0), {})
    work = [predict_run(fit.params, fit.terms(), np.zeros(4), r, RESOLUTION)[2] for r in recordings]
    return recordings, fit, work


def test_the_limit_bounds_the_runs_along_all_recordings_together(case):
    recordings, fit, (first, second) = case
    enough = tip_errors(fit, recordings, RESOLUTION, first + second)
    assert all(np.isfinite(e).all() for e in enough)
    # each run alone is under this limit, both together are over it
    limit = max(first, second) + min(first, second) // 2
    assert first <= limit and second <= limit < first + second
    errors = tip_errors(fit, recordings, RESOLUTION, limit)
    assert np.isfinite(errors[0]).all() and np.isinf(errors[1]).all()


def test_a_remembered_run_obeys_the_limit_asked_for(case):
    recordings, fit, (first, _) = case
    tips, _, work = predict_run(fit.params, fit.terms(), np.zeros(4), recordings[0], RESOLUTION)
    assert work == first
    with pytest.raises(SolverBudgetExceeded):
        predict_run(fit.params, fit.terms(), np.zeros(4), recordings[0], RESOLUTION, first - 1)
    again, _, work_again = predict_run(fit.params, fit.terms(), np.zeros(4), recordings[0], RESOLUTION, first)
    assert work_again == first and np.array_equal(again, tips)


def test_a_held_out_run_may_take_what_the_start_or_the_fit_itself_took_per_training_sample():
    """A fit with a compliant drive line takes more Newton iterations per step than its start: its
    held-out limit follows the larger of the two training limits, scaled by held-out over training samples."""
    train, holdout = [bending_recording("train", 1.0)], [bending_recording("held", 1.5)]
    assert holdout_iteration_limit(2000, 6000, train, holdout) == 9000
    assert holdout_iteration_limit(6000, 2000, train, holdout) == 9000
    assert holdout_iteration_limit(10, 20, train, holdout) == MIN_ITERATION_LIMIT


def test_the_remembered_runs_stay_within_their_bytes_forgetting_the_least_recently_used(monkeypatch):
    run_bytes = 20 * 7 * 8 + simulation._RunMemory.KEY_BYTES    # 20 samples of tips (3) and tensions (4)
    monkeypatch.setattr(simulation, "RUN_MEMORY_BYTES", 3 * run_bytes)
    memory = simulation._RunMemory()

    def run(iterations):
        return simulation._Outcome(np.zeros((20, 3)), np.zeros((20, 4)), iterations, False)

    for key in "abc":
        memory.remember(key, run(1))
    assert memory.get("a") is not None            # now the most recently used
    memory.remember("d", run(2))
    assert memory.get("b") is None and all(memory.get(key) is not None for key in "acd")
    memory.remember("d", run(3))                  # the same key again replaces, not adds
    assert memory.nbytes == 3 * run_bytes and memory.get("d").iterations == 3
    failed = simulation._Outcome(None, None, 10, False)
    for key in range(100):                        # failed runs have no tips, but count too
        memory.remember(key, failed)
    assert memory.nbytes <= 3 * run_bytes and len(memory.runs) == 3 * run_bytes // simulation._RunMemory.KEY_BYTES
