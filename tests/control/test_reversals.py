"""Issue 5, claim 2: point-to-point moves that reverse direction.

The same target (90 deg articulation) is reached from below (0 -> 90), from above
(150 -> 90) and from below again (30 -> 90). Under constant-curvature control the plant's
tip lands in different places depending on the direction of approach (Dahl hysteresis).
The friction-aware feedforward carries the friction state along the path and removes most
of that path-dependent offset.
"""
import math

import numpy as np
import pytest

from control import Articulation, make_controller
from control.trajectories import point_to_point
from tests.control.closed_loop import CONTROLLER_ELEMENTS, make_plant, run_loop


@pytest.fixture(scope="module")
def offsets(params, workspace, limits):
    waypoints = [Articulation(math.radians(deg), 0.0, 80.0) for deg in (90, 150, 90, 30, 90)]
    trajectory = point_to_point(workspace, limits, waypoints=waypoints, tendon_velocity_mm_s=10.0,
                                tendon_acceleration_mm_s2=100.0, hold_s=0.3)
    result = {}
    for name in ("cc", "dahl"):
        record = run_loop(make_controller(name, workspace, limits, n_elements=CONTROLLER_ELEMENTS), trajectory,
                          make_plant(params))
        from_below, from_above, again = (record.last_tip_of(f"hold {i}") for i in (1, 3, 5))
        result[name] = (float(np.linalg.norm(from_below - from_above)), float(np.linalg.norm(from_above - again)))
    return result


def test_constant_curvature_leaves_a_path_dependent_offset(offsets):
    assert min(offsets["cc"]) > 5.0


def test_dahl_removes_most_of_the_path_dependent_offset(offsets):
    for cc, dahl in zip(offsets["cc"], offsets["dahl"]):
        print(f"offset between approaches to 90 deg: cc {cc:.2f} mm, dahl {dahl:.2f} mm "
              f"({100 * (1 - dahl / cc):.0f} % removed)")
        assert dahl <= 0.3 * cc
