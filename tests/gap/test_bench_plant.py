"""The gap benchmark's synthetic plant stays physical along the whole excitation it records."""
import numpy as np

from control.excitation import training_trajectory
from crest.config import load_testbed_config
from crest.experiment.workspace_from_config import limits_for, workspace_for
from model import CatheterParams, DahlCatheter
from model.dahl_friction import capstan_gain
from model.effects import combined_terms

CHUNK_SAMPLES = 100


def friction_excess_n(model: DahlCatheter, params: CatheterParams) -> float:
    """How far the largest friction force exceeds its steady-state bound (seed paper eq. 3),

        |F_ki| <= Fs = Fsc*h + 2 tanh(mu |b_i| / 2) * max(T_ki, 0)

    the most any friction element can hold (a clamped element holds less: F = -P with P < |F_dahl|)."""
    state = model.snapshot()
    h_mm = model.free_length_mm / model.n_elements
    theta_rad = np.linalg.norm(state.bend_rad, axis=1)
    gain = np.array([capstan_gain(params.mu, t) for t in theta_rad])
    bound_n = params.fsc_n_per_mm * h_mm + gain[None, :] * np.clip(state.tension_n, 0.0, None)
    return float((np.abs(state.friction_n) - bound_n).max())


def test_no_element_holds_more_than_its_friction_along_the_bench_excitation():
    """The synthetic log of `crest bench --only gap` (prior with mu 0.25, 0.4 mm backlash, 100 Hz):
    until the clamp on friction's floor (F >= -P) was checked against the Dahl force, a converged
    solve at 75.6 s let clamped elements hold 92 N with 0 N at the drive (tip jump 40 mm), and every
    sample after it diverged to 1e11 N. Every 100 samples up to 80 s, no element holds more than its
    friction allows and the tip moves continuously."""
    config = load_testbed_config()
    params = CatheterParams.from_toml()
    trajectory = training_trajectory(workspace_for(config, params), limits_for(config), 0.01)
    plant = params.replace(mu=0.25, free_length_mm=float(trajectory.insertion_mm[0]))
    model = DahlCatheter(plant, 20, combined_terms({"backlash": (0.4,)}))
    n_samples = min(len(trajectory), 8000)
    previous_tip = model.tip_mm
    for start in range(0, n_samples, CHUNK_SAMPLES):
        stop = min(start + CHUNK_SAMPLES, n_samples)
        tips = model.run(trajectory.tendon_mm[start:stop], trajectory.insertion_mm[start:stop], 0.01)
        assert friction_excess_n(model, plant) < 1e-3, f"sample {stop}"
        steps_mm = np.linalg.norm(np.diff(np.vstack([previous_tip, tips]), axis=0), axis=1)
        assert steps_mm.max() < 5.0, f"tip jump of {steps_mm.max():.1f} mm before sample {stop}"
        previous_tip = tips[-1]
    assert model.solver_iterations[1] == 0
