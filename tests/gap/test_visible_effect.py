"""The visible part of an effect: what the calibrated base model cannot take up (crest.gap.visible_effect).

A catheter of another stiffness is what the base model's parameters describe, so it leaves
nothing visible however far it moves the tip; a tracker offset along the catheter's axis is
nothing a straight catheter can produce: the base model takes up some of it where the catheter
bends (a straighter catheter reaches further along the axis, but also less far sideways), most
of it stays visible."""
import dataclasses

import numpy as np
import pytest

from crest.gap.visible_effect import visible_effect_mm
from model import CatheterParams
from model.gap.diagnosis import DiagnosisSettings
from tests.gap.test_calibration import RESOLUTION, noiseless_recording

SETTINGS = DiagnosisSettings(resolution=RESOLUTION, baseline_iterations=20)


@pytest.fixture(scope="module")
def plain():
    return noiseless_recording(CatheterParams.from_toml())


def test_a_stiffer_catheter_moves_the_tip_but_leaves_nothing_visible(plain):
    prior = CatheterParams.from_toml()
    stiffer = noiseless_recording(prior.replace(bending_stiffness_nmm2=2.0 * prior.bending_stiffness_nmm2))
    moved_mm = float(np.sqrt(np.mean(np.sum((stiffer.tip_mm - plain.tip_mm) ** 2, axis=1))))
    assert moved_mm > 1.0
    assert visible_effect_mm(stiffer, plain, prior, SETTINGS) < 0.1 * moved_mm


def test_an_offset_along_the_axis_stays_visible(plain):
    offset = dataclasses.replace(plain, tip_mm=plain.tip_mm + np.array([0.0, 0.0, 1.0]))
    visible = visible_effect_mm(offset, plain, CatheterParams.from_toml(), SETTINGS)
    assert 0.6 < visible <= 1.0
