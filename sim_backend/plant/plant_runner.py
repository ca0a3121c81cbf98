"""Steps a plant from the drives' positions, in step with SYNC or in its own thread.

A plant may be much slower than the bus (a Cosserat rod can take milliseconds per step). In
threaded mode the runner steps it as fast as it can with the real elapsed time as dt, while the
drives answer every SYNC with the latest output; `achieved_rate_hz` reports what the plant held.
In synchronous mode (deterministic tests) the testbed calls `step(dt_s)` once per SYNC.
"""
from __future__ import annotations

import threading
import time

import numpy as np

from sim_backend.plant.plant_protocol import Plant


class PlantError(RuntimeError):
    """The plant failed or returned something that is not (tip_mm[3], tendon_tension_n[4]), finite."""


class PlantRunner:
    def __init__(self, plant: Plant, tendon_mm, insertion_mm: float):
        self.plant = plant
        self._lock = threading.Lock()
        self._tendon_mm = np.asarray(tendon_mm, dtype=float).copy()
        self._insertion_mm = float(insertion_mm)
        self._tip_mm = np.full(3, np.nan)
        self._tension_n = np.zeros(4)
        self._steps = 0
        self._started_s = time.monotonic()
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()
        self.error: PlantError | None = None
        self.plant.reset()
        self.step(0.0)

    # -- inputs and outputs (thread-safe) -------------------------------------------------------
    def set_inputs(self, tendon_mm, insertion_mm: float) -> None:
        with self._lock:
            self._tendon_mm[:] = tendon_mm
            self._insertion_mm = float(insertion_mm)

    def latest(self) -> tuple[np.ndarray, np.ndarray]:
        """The latest (tip_mm, tendon_tension_n), as copies."""
        with self._lock:
            return self._tip_mm.copy(), self._tension_n.copy()

    def tip_mm(self) -> np.ndarray:
        return self.latest()[0]

    @property
    def achieved_rate_hz(self) -> float:
        elapsed = time.monotonic() - self._started_s
        return self._steps / elapsed if elapsed > 0 else 0.0

    # -- stepping -----------------------------------------------------------------------------
    def step(self, dt_s: float) -> None:
        """One plant step to the current inputs; raises PlantError on a bad output."""
        with self._lock:
            tendon = self._tendon_mm.copy()
            insertion = self._insertion_mm
        try:
            tip, tension = self.plant.step(dt_s, tendon, insertion)
            tip = np.asarray(tip, dtype=float).reshape(3)
            tension = np.asarray(tension, dtype=float).reshape(4)
        except Exception as exc:  # any plant failure, user plants included, becomes one PlantError
            raise PlantError(f"plant {type(self.plant).__name__}.step failed: {exc}") from exc
        if not (np.isfinite(tip).all() and np.isfinite(tension).all()):
            raise PlantError(f"plant {type(self.plant).__name__} returned a non-finite tip {tip} or tension {tension}")
        with self._lock:
            self._tip_mm = tip
            self._tension_n = tension
            self._steps += 1

    def start_thread(self, min_period_s: float = 0.001) -> None:
        """Step in a background thread, no faster than 1/min_period_s."""
        self._stop.clear()
        self._steps = 0
        self._started_s = time.monotonic()
        self._thread = threading.Thread(target=self._loop, args=(min_period_s,), name="plant", daemon=True)
        self._thread.start()

    def stop_thread(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)
            self._thread = None

    def _loop(self, min_period_s: float) -> None:
        last = time.monotonic()
        while not self._stop.is_set():
            now = time.monotonic()
            try:
                self.step(now - last)
            except PlantError as exc:
                self.error = exc
                return
            last = now
            spare = min_period_s - (time.monotonic() - now)
            if spare > 0:
                self._stop.wait(spare)
