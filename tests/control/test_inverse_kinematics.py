"""The constant-curvature inverse: tip <-> articulation <-> tendons."""
import math

import numpy as np
import pytest

from model import ConstantCurvature

from control import (Articulation, ControlInputError, articulation_from_pitch_yaw, articulation_from_tip,
                     tendons_from_articulation, tip_from_articulation)
from control.inverse_kinematics import pulls_from_tendons


def test_tip_to_articulation_round_trip(params):
    rng = np.random.default_rng(0)
    for _ in range(200):
        articulation = Articulation(rng.uniform(0, 1.9 * math.pi), rng.uniform(-math.pi, math.pi),
                                    rng.uniform(10, 100))
        back = articulation_from_tip(tip_from_articulation(articulation, params))
        assert back.theta_rad == pytest.approx(articulation.theta_rad, abs=1e-9)
        assert back.insertion_mm == pytest.approx(articulation.insertion_mm, rel=1e-9)
        assert np.allclose(back.bend_rad, articulation.bend_rad, atol=1e-9)


def test_straight_and_half_circle_have_the_textbook_tips(params):
    assert np.allclose(tip_from_articulation(Articulation(0.0, 0.0, 80.0), params), [0, 0, 80])
    # 180 deg: a half circle of radius L/pi puts the tip 2L/pi to the side, level with the tube exit
    assert np.allclose(tip_from_articulation(Articulation(math.pi, 0.0, 80.0), params), [160 / math.pi, 0, 0],
                       atol=1e-9)


def test_tendon_commands_match_the_model_and_keep_the_pretension(params):
    articulation = Articulation(math.radians(120), 0.7, 65.0)
    tendons = tendons_from_articulation(articulation, params.tendon_offset_mm, 0.02)
    assert np.allclose(tendons[0] + tendons[2], 0.04) and np.allclose(tendons[1] + tendons[3], 0.04)
    assert np.allclose(pulls_from_tendons(tendons), params.tendon_offset_mm * articulation.bend_rad)
    model_tip = ConstantCurvature(params).tip_mm(tendons, articulation.insertion_mm)
    assert np.allclose(model_tip, tip_from_articulation(articulation, params))


def test_pitch_bends_toward_tendon_1_and_yaw_toward_tendon_2(params):
    pitch = tip_from_articulation(articulation_from_pitch_yaw(0.5, 0.0, 80.0), params)
    yaw = tip_from_articulation(articulation_from_pitch_yaw(0.0, 0.5, 80.0), params)
    assert pitch[0] > 10 and abs(pitch[1]) < 1e-9
    assert yaw[1] > 10 and abs(yaw[0]) < 1e-9


@pytest.mark.parametrize("tip", [(0.0, 0.0, -30.0), (0.0, 0.0, 0.0), (np.nan, 1.0, 50.0), (1.0, 2.0)])
def test_unreachable_or_malformed_tip_is_refused(tip):
    with pytest.raises(ControlInputError, match="tip"):
        articulation_from_tip(tip)
