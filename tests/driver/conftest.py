"""Fixtures for the driver tests (the rig itself is in driver_rig.py)."""

from __future__ import annotations

import pytest

from crest.config import TestbedConfig
from driver_rig import Rig, drive_specs, make_config
from sim_backend.drive.drive_spec import DriveSpec


@pytest.fixture
def config() -> TestbedConfig:
    return make_config()


@pytest.fixture
def make_rig():
    """Factory: make_rig(config=None, specs=None, faults=()) -> Rig, closed after the test."""
    rigs = []

    def make(config: TestbedConfig | None = None, specs: list[DriveSpec] | None = None, faults=()) -> Rig:
        config = config if config is not None else make_config()
        rig = Rig(config, specs if specs is not None else drive_specs(config), faults)
        rigs.append(rig)
        return rig

    yield make
    for rig in rigs:
        rig.close()


@pytest.fixture
def booted(make_rig) -> Rig:
    rig = make_rig()
    rig.testbed.boot()
    return rig


@pytest.fixture
def homed(booted) -> Rig:
    booted.testbed.home()
    return booted
