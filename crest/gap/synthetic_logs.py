"""Record crest logs from a model plant directly: a fast stand-in for `crest excite` on the
virtual testbed, for the tests and `crest bench` (the blind benchmark uses the testbed itself).

The plant is a fine DahlCatheter (20 elements) with its own base parameters, tendon zero
offsets and any candidate effects switched on. The drives follow the constant-curvature
set-points exactly and report them; the tracker adds Gaussian noise and drops samples; the
drive tension is reported with noise. The log records only what a testbed would: which
effect the plant has is never written (the sidecar says "model plant", nothing more).
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from control.trajectories import Trajectory
from crest.log import LogWriter, catheter_dict
from model import CatheterParams, DahlCatheter
from model.effects import combined_terms


@dataclass(frozen=True)
class SensorNoise:
    """Measurement imperfections of the virtual testbed (per axis std in mm, force std in N)."""

    tip_mm: float = 0.1
    dropout_fraction: float = 0.01
    tendon_force_n: float = 0.05


@dataclass(frozen=True)
class Plant:
    """The catheter behind the drives: base parameters, zero offsets and effects {id: values}."""

    params: CatheterParams
    effects: Mapping[str, tuple[float, ...]] = field(default_factory=dict)
    zero_offsets_mm: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    n_elements: int = 20


def record_plant_log(path: Path | str, trajectory: Trajectory, plant: Plant, noise: SensorNoise,
                     rng: np.random.Generator, *, overwrite: bool = False) -> Path:
    """Drive the plant along the trajectory's constant-curvature tendon commands and write what the
    testbed would log; returns the CSV path."""
    tendon_pos = trajectory.tendon_mm
    insertion_pos = trajectory.insertion_mm
    params = plant.params.replace(free_length_mm=float(insertion_pos[0]))
    catheter = DahlCatheter(params, plant.n_elements, combined_terms(plant.effects))
    u = tendon_pos - np.asarray(plant.zero_offsets_mm)
    dt_s = trajectory.period_s
    n = len(trajectory)
    tips, force = catheter.run_with_tension(u, insertion_pos, dt_s)
    tips += rng.normal(0.0, noise.tip_mm, tips.shape)
    tips[rng.random(n) < noise.dropout_fraction] = np.nan
    force += rng.normal(0.0, noise.tendon_force_n, force.shape)
    sidecar_catheter = catheter_dict(flexible_length_mm=plant.params.max_free_length_mm,
                                     tendon_offset_mm=plant.params.tendon_offset_mm,
                                     outer_diameter_mm=plant.params.outer_diameter_mm)
    with LogWriter(path, catheter=sidecar_catheter, sample_rate_hz=1.0 / dt_s, source="model plant",
                   notes="excitation", tendon_force=True, overwrite=overwrite) as writer:
        for t in range(n):
            writer.write(trajectory.t_s[t] - trajectory.t_s[0], tendon_pos[t], insertion_pos[t], tendon_pos[t],
                         insertion_pos[t], None if np.isnan(tips[t, 0]) else tips[t], tendon_force_n=force[t])
    return writer.path
