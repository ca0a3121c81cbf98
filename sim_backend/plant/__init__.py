"""The plant behind the virtual drives: protocol, default Dahl catheter, loader, runner."""
from sim_backend.plant.dahl_plant import DahlPlant, PlantConfig, PlantConfigError
from sim_backend.plant.plant_loader import PlantLoadError, load_plant
from sim_backend.plant.plant_protocol import Plant
from sim_backend.plant.plant_runner import PlantError, PlantRunner

__all__ = ["DahlPlant", "Plant", "PlantConfig", "PlantConfigError", "PlantError", "PlantLoadError",
           "PlantRunner", "load_plant"]
