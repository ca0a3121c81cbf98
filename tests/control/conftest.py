import pytest

from model import CatheterParams

from control import MotionLimits, Workspace

PRETENSION_MM = 0.02   # configs/testbed.toml [coordination].pretension_mm


@pytest.fixture(scope="session")
def params() -> CatheterParams:
    return CatheterParams.from_toml()


@pytest.fixture(scope="session")
def workspace(params) -> Workspace:
    return Workspace.from_params(params, pretension_mm=PRETENSION_MM)


@pytest.fixture(scope="session")
def limits() -> MotionLimits:
    return MotionLimits()
