"""Benchmark of the rod plant family: its step rate against the 100 Hz SYNC it runs behind."""
from __future__ import annotations

import re
import tempfile
import time
from pathlib import Path

import numpy as np

from crest.backend import plant_from_description

ROD_PLANT_TOML = Path(__file__).resolve().parents[2] / "configs" / "rod_plant.toml"
SYNC_RATE_HZ = 100.0


def articulation_pull_mm(duration_s: float = 10.0, peak_mm: float = 6.0) -> np.ndarray:
    """Tendon 1 pulled to peak_mm (~150 deg at 80 mm) and back at 100 Hz; tendon 3 paid out as much."""
    pull = peak_mm * np.sin(np.linspace(0.0, np.pi, int(duration_s * SYNC_RATE_HZ)))
    return np.column_stack([pull, np.zeros_like(pull), -pull, np.zeros_like(pull)])


def rod_plant_step(grid_nodes: int, repeats: int = 3, free_length_mm: float = 80.0) -> dict:
    """Best wall time of stepping configs/rod_plant.toml (with grid_nodes nodes) over the path."""
    text = re.sub(r"(?m)^grid_nodes\s*=.*$", f"grid_nodes = {grid_nodes}", ROD_PLANT_TOML.read_text())
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "rod_plant.toml"
        path.write_text(text)
        plant = plant_from_description(path)
    path_mm = articulation_pull_mm()
    dt_s = 1.0 / SYNC_RATE_HZ
    plant.step(dt_s, path_mm[1], free_length_mm)     # warm-up (loads the compiled kernel)
    best_s = best_cpu_s = np.inf
    for _ in range(repeats):
        plant.reset()
        start, start_cpu = time.perf_counter(), time.process_time()
        for tendon_mm in path_mm:
            plant.step(dt_s, tendon_mm, free_length_mm)
        best_s = min(best_s, time.perf_counter() - start)
        best_cpu_s = min(best_cpu_s, time.process_time() - start_cpu)
    rate_hz = len(path_mm) / best_s
    # steps per second of this process's CPU time: what one unloaded core would hold
    return {"grid_nodes": grid_nodes, "steps": len(path_mm), "wall_s": best_s, "cpu_s": best_cpu_s,
            "step_rate_hz": rate_hz, "step_rate_per_cpu_s": len(path_mm) / best_cpu_s,
            "real_time_factor_at_100_hz": rate_hz / SYNC_RATE_HZ, "goal_step_rate_hz": SYNC_RATE_HZ}


def rod_plant(sizes=(200, 400)) -> dict:
    return {str(n): rod_plant_step(n) for n in sizes}
