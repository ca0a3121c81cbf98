"""Load a plant named `package.module:ClassName` (the `--plant` option)."""
from __future__ import annotations

import importlib

from sim_backend.plant.plant_protocol import Plant


class PlantLoadError(ValueError):
    """The named plant cannot be imported, built with no arguments, or lacks reset/step."""


def load_plant(spec: str) -> Plant:
    module_name, sep, class_name = spec.partition(":")
    if not sep or not module_name or not class_name:
        raise PlantLoadError(f"--plant {spec!r}: expected 'package.module:ClassName'")
    try:
        module = importlib.import_module(module_name)
    except ImportError as exc:
        raise PlantLoadError(f"--plant {spec!r}: cannot import module {module_name!r}: {exc}") from exc
    cls = getattr(module, class_name, None)
    if cls is None:
        raise PlantLoadError(f"--plant {spec!r}: module {module_name!r} has no {class_name!r}")
    try:
        plant = cls()
    except Exception as exc:  # a user's constructor can fail in any way; report it as a load error
        raise PlantLoadError(f"--plant {spec!r}: {class_name}() failed: {exc}") from exc
    if not isinstance(plant, Plant):
        raise PlantLoadError(f"--plant {spec!r}: {class_name} needs reset() and "
                             f"step(dt_s, tendon_mm, insertion_mm) -> (tip_mm, tendon_tension_n)")
    return plant
