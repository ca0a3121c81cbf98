"""The tip as the tracker sees it: p_tip + R_tip d + o. The sensor's mount offset d (effect
`sensor_offset`) turns with the tip; the registration offset o (effect `tracker_offset`) does not."""
import numpy as np

from model import DahlCatheter, EffectTerms
from tests.model.conftest import articulation

MOUNT_MM = (0.0, 0.0, 2.0)              # a coil 2 mm beyond the tip centre, on the tip's axis
REGISTRATION_MM = (1.0, -0.5, 0.25)


def test_the_sensor_offset_is_the_mount_offset_when_straight_and_turns_with_a_bend(params):
    plain = DahlCatheter(params)
    mounted = DahlCatheter(params, effects=EffectTerms(sensor_offset_mm=MOUNT_MM))
    straight = np.zeros(4)
    assert np.allclose(mounted.move_to(straight) - plain.move_to(straight), MOUNT_MM, atol=1e-12)

    bend = articulation(params, 90.0)
    difference_mm = mounted.move_to(bend) - plain.move_to(bend)
    tip_axis = plain.state.frames[-1][:, 2]
    assert np.allclose(difference_mm, 2.0 * tip_axis, atol=1e-9)
    assert np.arctan2(tip_axis[0], tip_axis[2]) > np.deg2rad(45.0)   # far enough that a fixed offset would be wrong
    assert np.allclose(mounted.tip_mm - plain.tip_mm, difference_mm, atol=1e-12)


def test_the_tracker_offset_is_the_same_constant_at_every_bend(params):
    plain = DahlCatheter(params)
    registered = DahlCatheter(params, effects=EffectTerms(tracker_offset_mm=REGISTRATION_MM))
    for degrees in (0.0, 90.0, 150.0):
        bend = articulation(params, degrees)
        assert np.allclose(registered.move_to(bend) - plain.move_to(bend), REGISTRATION_MM, atol=1e-12)
        assert np.allclose(registered.tip_mm - plain.tip_mm, REGISTRATION_MM, atol=1e-12)
