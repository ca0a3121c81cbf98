import numpy as np
import pytest

from model import CatheterParams, tendons_from_articulation


@pytest.fixture(scope="session")
def params() -> CatheterParams:
    return CatheterParams.from_toml()


def articulation(params, degrees, plane_deg=0.0, pretension_mm=0.0):
    """Tendon input for a constant-curvature articulation of `degrees` in the plane `plane_deg`."""
    return tendons_from_articulation(np.deg2rad(degrees), np.deg2rad(plane_deg), params.tendon_offset_mm,
                                     pretension_mm)


def tip_angle_rad(tips):
    """Tip bend angle seen from the base, unwrapped, in the x-z plane."""
    return np.unwrap(np.arctan2(tips[:, 0], tips[:, 2]))
