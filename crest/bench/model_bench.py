"""Benchmarks of the model: step rate (quasi-static and dynamic), real-time factor, cost against N, one move."""
from __future__ import annotations

import time

import numpy as np

from model import CatheterParams, DahlCatheter, tendons_from_articulation

SAMPLE_RATE_HZ = 100.0
REFERENCE_TIME_STEP_S = 0.0003125   # the dynamic mode's time steps are scored against runs with this step


def articulation_path(params: CatheterParams, duration_s: float = 10.0, peak_deg: float = 150.0) -> np.ndarray:
    """A 100 Hz articulation to peak_deg and back over duration_s: tendon set-points [T, 4]."""
    n = int(duration_s * SAMPLE_RATE_HZ)
    theta = np.deg2rad(peak_deg) * np.sin(np.linspace(0.0, np.pi, n))
    return np.array([tendons_from_articulation(t, 0.0, params.tendon_offset_mm, 0.02) for t in theta])


def time_run_s(params: CatheterParams, n_elements: int, path: np.ndarray, repeats: int = 15) -> float:
    """Best wall time of `run` over the path (after one warm-up that also compiles).

    The best of many short runs (a 10 s path takes about 10 ms) is the model's own cost: on a
    shared machine single runs vary by 10% with the neighbours' load, and the best of 3 by 4%.
    """
    model = DahlCatheter(params, n_elements)
    model.run(path[:10])
    best = np.inf
    for _ in range(repeats):
        model.reset()
        start = time.perf_counter()
        model.run(path)
        best = min(best, time.perf_counter() - start)
    return best


def model_step(params: CatheterParams) -> dict:
    """Real-time factor at N = 20: seconds of 100 Hz input simulated per wall-clock second."""
    path = articulation_path(params)
    wall_s = time_run_s(params, 20, path)
    duration_s = len(path) / SAMPLE_RATE_HZ
    return {"n_elements": 20, "samples": len(path), "wall_s": wall_s,
            "step_rate_hz": len(path) / wall_s, "real_time_factor": duration_s / wall_s,
            "goal_real_time_factor": 1000.0}


def dynamic_model_step(params: CatheterParams, damping_time_s: float = 0.02, inertia_scale: float = 1.0) -> dict:
    """model_step in the dynamic mode (backward Euler, steps of at most 10 ms: one per 10 ms sample),
    with the default step's error on fast inputs (time_step_error).

    Unless the parameters already set them, a 20 ms damping time and the catheter's own mass.
    """
    if not params.dynamic:
        params = params.replace(damping_time_s=damping_time_s, inertia_scale=inertia_scale)
    result = model_step(params)
    max_time_step_s = DahlCatheter(params, 20).max_time_step_s
    result.update(damping_time_s=params.damping_time_s, inertia_scale=params.inertia_scale,
                  max_time_step_s=max_time_step_s, reference_time_step_s=REFERENCE_TIME_STEP_S,
                  time_step_rms_error_mm=time_step_error(params, (max_time_step_s,))[max_time_step_s])
    return result


def fast_inputs(params: CatheterParams, duration_s: float = 4.0) -> dict[str, np.ndarray]:
    """Two fast 100 Hz inputs [T, 4]: a 120 deg step at 0.5 s, and a two-tone multisine about 60 deg
    pulling at up to 18 mm/s."""
    t = np.arange(0.0, duration_s, 1.0 / SAMPLE_RATE_HZ)
    angles_deg = {
        "step_120_deg": np.where(t > 0.5, 120.0, 0.0),
        "multisine": 60.0 * (1 + 0.6 * np.sin(2 * np.pi * 0.8 * t) + 0.3 * np.sin(2 * np.pi * 2.1 * t))
        * (1 - np.exp(-t / 0.3))}
    return {name: np.array([tendons_from_articulation(np.deg2rad(a), 0.0, params.tendon_offset_mm, 0.02)
                            for a in angles]) for name, angles in angles_deg.items()}


def time_step_error(params: CatheterParams, steps_s, reference_step_s: float = REFERENCE_TIME_STEP_S) -> dict:
    """{step [s]: {input: tip RMS error [mm]}} of the dynamic model run with time steps of at most
    step_s on the fast_inputs, against runs with steps of reference_step_s:

        e = sqrt(mean_t |p_step(t) - p_ref(t)|^2)
    """
    errors: dict = {step_s: {} for step_s in steps_s}
    for name, path in fast_inputs(params).items():
        reference = DahlCatheter(params, max_time_step_s=reference_step_s).run(path)
        for step_s in steps_s:
            tips = DahlCatheter(params, max_time_step_s=step_s).run(path)
            errors[step_s][name] = float(np.sqrt(np.mean(np.sum((tips - reference) ** 2, axis=1))))
    return errors


def scaling_in_n(params: CatheterParams, sizes=(10, 20, 40, 80, 160, 320)) -> dict:
    """Cost per sample against N and the exponent p of cost ~ N^p (least squares in log-log)."""
    path = articulation_path(params, duration_s=4.0)
    per_sample_us = [time_run_s(params, n, path, repeats=2) / len(path) * 1e6 for n in sizes]
    exponent = float(np.polyfit(np.log(sizes), np.log(per_sample_us), 1)[0])
    return {"n_elements": list(sizes), "per_sample_us": per_sample_us, "cost_exponent": exponent,
            "goal_cost_exponent": 1.1}


def quasi_static_move(params: CatheterParams) -> dict:
    """Wall time of one move_to from 0 to 180 deg (sub-stepped to follow the friction history)."""
    model = DahlCatheter(params)
    target = tendons_from_articulation(np.pi, 0.0, params.tendon_offset_mm, 0.02)
    model.move_to(target)
    times = []
    for _ in range(5):
        model.reset()
        start = time.perf_counter()
        model.move_to(target)
        times.append(time.perf_counter() - start)
    return {"from_deg": 0, "to_deg": 180, "wall_ms": 1e3 * min(times)}
