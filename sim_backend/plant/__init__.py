"""The plant behind the virtual drives: protocol, plant families (Dahl, rod), loaders, runner.

The Dahl family (dahl_plant.py) imports `model`; it is loaded on first use, so importing the
independent rod family (sim_backend.plant.rod) never imports `model`.
"""
from importlib import import_module

from sim_backend.plant.plant_loader import PlantLoadError, load_plant
from sim_backend.plant.plant_protocol import Plant
from sim_backend.plant.plant_runner import PlantError, PlantRunner

_ON_FIRST_USE = {"DahlPlant": "sim_backend.plant.dahl_plant", "PlantConfig": "sim_backend.plant.dahl_plant",
                 "PlantConfigError": "sim_backend.plant.dahl_plant"}

__all__ = ["DahlPlant", "Plant", "PlantConfig", "PlantConfigError", "PlantError", "PlantLoadError",
           "PlantRunner", "load_plant"]


def __getattr__(name: str):
    if name in _ON_FIRST_USE:
        return getattr(import_module(_ON_FIRST_USE[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
