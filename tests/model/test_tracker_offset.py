"""The tip sensor's mount offset (effect `tracker_offset`) turns with the tip: p_tip + R_tip d."""
import numpy as np

from model import DahlCatheter, EffectTerms
from tests.model.conftest import articulation

OFFSET_MM = (0.0, 0.0, 2.0)     # a coil 2 mm beyond the tip centre, on the tip's axis


def test_the_sensor_offset_is_the_mount_offset_when_straight_and_turns_with_a_bend(params):
    plain = DahlCatheter(params)
    mounted = DahlCatheter(params, effects=EffectTerms(tracker_offset_mm=OFFSET_MM))
    straight = np.zeros(4)
    assert np.allclose(mounted.move_to(straight) - plain.move_to(straight), OFFSET_MM, atol=1e-12)

    bend = articulation(params, 90.0)
    difference_mm = mounted.move_to(bend) - plain.move_to(bend)
    tip_axis = plain.state.frames[-1][:, 2]
    assert np.allclose(difference_mm, 2.0 * tip_axis, atol=1e-9)
    tip_angle_rad = np.arctan2(tip_axis[0], tip_axis[2])
    assert np.deg2rad(45.0) < tip_angle_rad       # bent far enough that a fixed offset would be wrong
    assert np.allclose(mounted.tip_mm - plain.tip_mm, difference_mm, atol=1e-12)
