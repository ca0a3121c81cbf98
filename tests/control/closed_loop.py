"""The model-level closed loop the control tests run: controller -> plant, cycle by cycle at 100 Hz.

The plant is a second DahlCatheter whose parameters differ from the controller's by 12-20%
(friction coefficient +15 %, bending stiffness -12 %, Dahl stiffness +20 %), with finer
elements (20 against the controller's 10) and one unmodelled effect switched on: gravity
(sag under the catheter's own weight). The tracker sample handed to the controller in cycle
k is the plant's tip after command k-1, plus Gaussian noise, taken 5 ms before the cycle.
The plant moves one SYNC period per command (rate-dependent effects see the real speed).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from model import CatheterParams, DahlCatheter
from model.effects import EFFECTS

from control import Controller, TipMeasurement
from control.trajectories import Trajectory

CONTROLLER_ELEMENTS = 10
PLANT_ELEMENTS = 20
UNMODELLED_EFFECT = "gravity"
SAMPLE_DELAY_S = 0.005


def plant_params(params: CatheterParams) -> CatheterParams:
    return params.replace(mu=params.mu * 1.15, bending_stiffness_nmm2=params.bending_stiffness_nmm2 * 0.88,
                          sigma_n_per_mm2=params.sigma_n_per_mm2 * 1.2)


def make_plant(params: CatheterParams) -> DahlCatheter:
    effect = EFFECTS[UNMODELLED_EFFECT]
    return DahlCatheter(plant_params(params), PLANT_ELEMENTS, effects=effect.terms(effect.typical))


@dataclass
class LoopRecord:
    """Per cycle: the plant's true tip after the command, the target, the controller's estimate."""

    tip_mm: np.ndarray
    target_mm: np.ndarray
    estimate_mm: np.ndarray
    tendon_mm: np.ndarray
    labels: list[str]

    def rms_error_mm(self, label: str | None = None) -> float:
        error = np.linalg.norm(self.tip_mm - self.target_mm, axis=1)
        if label is not None:
            error = error[np.array([lab == label for lab in self.labels])]
        return float(np.sqrt(np.mean(error ** 2)))

    def last_tip_of(self, label: str) -> np.ndarray:
        return self.tip_mm[max(k for k, lab in enumerate(self.labels) if lab == label)]


def run_loop(controller: Controller, trajectory: Trajectory, plant: DahlCatheter, *, noise_mm: float = 0.0,
             dropout: float = 0.0, seed: int = 0) -> LoopRecord:
    rng = np.random.default_rng(seed)
    controller.reset()
    plant.reset()
    tips, estimates, tendons = [], [], []
    for setpoint in trajectory:
        sample = None
        if rng.random() >= dropout:
            sample = TipMeasurement(plant.tip_mm + rng.normal(0.0, noise_mm, 3) if noise_mm > 0 else plant.tip_mm,
                                    setpoint.t_s - SAMPLE_DELAY_S)
        command = controller.command(setpoint, sample)
        tips.append(plant.run(command.tendon_mm[np.newaxis], [command.insertion_mm], dt_s=trajectory.period_s)[0])
        estimates.append(command.predicted_tip_mm)
        tendons.append(command.tendon_mm)
    return LoopRecord(np.array(tips), trajectory.tip_mm, np.array(estimates), np.array(tendons),
                      list(trajectory.labels))
