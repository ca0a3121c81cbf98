"""An independent plant family: a Kirchhoff-rod catheter with frictional, elastic tendons.

It shares no code with `model` (it imports nothing from it, directly or through another module),
so it can check the Dahl model against something that is not the Dahl model.
"""
from sim_backend.plant.rod.rod_description import DEFAULT_ROD_TOML, RodDescription, RodDescriptionError
from sim_backend.plant.rod.rod_effects import ROD_EFFECTS, RodEffectError, effect_ranges
from sim_backend.plant.rod.rod_plant import RodPlant, RodSolverError

__all__ = ["DEFAULT_ROD_TOML", "ROD_EFFECTS", "RodDescription", "RodDescriptionError", "RodEffectError",
           "RodPlant", "RodSolverError", "effect_ranges"]
