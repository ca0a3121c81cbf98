"""The diagnosis' coarse model (`Resolution`) is continuous in its parameters.

The path: the inputs of a held-out recording of the virtual testbed (circles through slack/taut
switches, 11 Hz), with the catheter a baseline fit found there. With 12 Newton iterations per
sub-step a 1e-9 relative change of EI moved the tip by 9 mm for a few samples (a spurious
equilibrium at a tendon's reversal), enough to swap the diagnosis' ranking of candidates.
"""
from pathlib import Path

import numpy as np
import pytest

from model import CatheterParams, SolverBudgetExceeded
from model.effect_terms import EffectTerms
from model.gap.recording import Recording
from model.gap.simulation import Resolution, predict_tips

PATH = Path(__file__).parent / "data" / "held_out_circles_path.csv"
SAMPLE_PERIOD_S = 0.09
FITTED = CatheterParams.from_toml().replace(bending_stiffness_nmm2=695.359054507092,
                                            axial_stiffness_n=119664.23580001431, mu=0.17295525756757046,
                                            fsc_n_per_mm=0.007327412904718217, sigma_n_per_mm2=1.9000443337389636,
                                            tendon_range_mm=(-14.4, 14.4))


def circles(samples: int | None = None) -> Recording:
    """The recorded inputs (tips unknown: zeros), as the diagnosis reads them."""
    inputs = np.loadtxt(PATH, delimiter=",", skiprows=1)[:samples]
    return Recording("circles", np.arange(len(inputs)) * SAMPLE_PERIOD_S, inputs[:, :4], inputs[:, 4],
                     np.zeros((len(inputs), 3)), None, 100.0, 2.5, 6.0)


def coarse_tips(params: CatheterParams, recording: Recording, iteration_limit: int | None = None) -> np.ndarray:
    return predict_tips(params, EffectTerms(), np.zeros(4), recording, Resolution(), iteration_limit)


@pytest.mark.parametrize("relative_change", [1e-9, -1e-9, 1e-6, -1e-6])
def test_a_tiny_stiffness_change_moves_the_tip_by_a_tiny_amount(relative_change):
    recording = circles()
    before = coarse_tips(FITTED, recording)
    after = coarse_tips(FITTED.replace(bending_stiffness_nmm2=FITTED.bending_stiffness_nmm2 * (1 + relative_change)),
                        recording)
    assert np.abs(after - before).max() < 0.01


def test_a_run_over_its_iteration_limit_is_given_up():
    recording = circles(100)
    assert np.isfinite(coarse_tips(FITTED, recording, iteration_limit=10 ** 6)).all()
    with pytest.raises(SolverBudgetExceeded, match="solver iterations"):
        coarse_tips(FITTED, recording, iteration_limit=10)
