"""The diagnosis' coarse model (`Resolution`) is continuous in its parameters.

The path: the inputs of a held-out recording of the virtual testbed (circles through slack/taut
switches, 11 Hz), with the catheter a baseline fit found there. With 12 Newton iterations per
sub-step a 1e-9 relative change of EI moved the tip by 9 mm for a few samples (a spurious
equilibrium at a tendon's reversal), enough to swap the diagnosis' ranking of candidates.
"""
from pathlib import Path

import numpy as np
import pytest

from model import CatheterParams, DahlCatheter
from model.effect_terms import EffectTerms
from model.gap.recording import Recording
from model.gap.simulation import Resolution, SimulationTooSlow, predict_tips

PATH = Path(__file__).parent / "data" / "held_out_circles_path.csv"
SAMPLE_PERIOD_S = 0.09
FITTED = CatheterParams.from_toml().replace(bending_stiffness_nmm2=695.359054507092, axial_stiffness_n=119664.23580001431,
                                            mu=0.17295525756757046, fsc_n_per_mm=0.007327412904718217,
                                            sigma_n_per_mm2=1.9000443337389636, tendon_range_mm=(-14.4, 14.4))


def coarse_tips(params: CatheterParams, inputs: np.ndarray) -> np.ndarray:
    res = Resolution()
    model = DahlCatheter(params.replace(free_length_mm=float(inputs[0, 4])), res.n_elements,
                         max_tendon_step_mm=res.max_tendon_step_mm, max_insertion_step_mm=res.max_insertion_step_mm,
                         max_newton_iterations=res.max_newton_iterations)
    return model.run(inputs[:, :4], inputs[:, 4], SAMPLE_PERIOD_S)


@pytest.mark.parametrize("relative_change", [1e-9, -1e-9, 1e-6, -1e-6])
def test_a_tiny_stiffness_change_moves_the_tip_by_a_tiny_amount(relative_change):
    inputs = np.loadtxt(PATH, delimiter=",", skiprows=1)
    before = coarse_tips(FITTED, inputs)
    after = coarse_tips(FITTED.replace(bending_stiffness_nmm2=FITTED.bending_stiffness_nmm2 * (1 + relative_change)),
                        inputs)
    assert np.abs(after - before).max() < 0.01


def test_a_run_over_its_iteration_limit_is_given_up():
    inputs = np.loadtxt(PATH, delimiter=",", skiprows=1)[:100]
    recording = Recording("circles", np.arange(len(inputs)) * SAMPLE_PERIOD_S, inputs[:, :4], inputs[:, 4],
                          np.zeros((len(inputs), 3)), None, 100.0, 2.5, 6.0)
    tips = predict_tips(FITTED, EffectTerms(), np.zeros(4), recording, Resolution(), iteration_limit=10 ** 6)
    assert np.isfinite(tips).all()
    with pytest.raises(SimulationTooSlow, match="solver iterations"):
        predict_tips(FITTED, EffectTerms(), np.zeros(4), recording, Resolution(), iteration_limit=10)
