"""The standard calibration and diagnosis experiment: the training and the held-out excitation
(control/excitation.py), one crest log each, on whatever testbed the session opened.

`crest excite` and the blind benchmark both record through here. Each excitation is run like
`crest run` runs a trajectory: the constant-curvature controller (open loop) turns every
set-point into tendon and insertion commands, one SYNC cycle per set-point, and the recorder
logs the measured drive positions, tensions and tracker tip of each cycle. Before each log the
conditioning spiral runs unrecorded, so that every log starts, like the model, with no friction
stored in the catheter.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from control.controllers.constant_curvature import ConstantCurvatureController
from control.excitation import (conditioning_trajectory, fast_input_trajectories, holdout_trajectory,
                                training_trajectory)
from control.trajectories import Trajectory
from crest.config import TestbedConfig
from crest.experiment.controlled_run import RunResult, run_with_controller
from crest.experiment.recorder import ExperimentRecorder
from crest.experiment.workspace_from_config import limits_for, workspace_for
from crest.session import Session
from model import CatheterParams

NOTES = "excitation for crest fit / crest gap"


@dataclass(frozen=True)
class ExcitationPlan:
    """The trajectories of the experiment: the unrecorded conditioning, and the logs by name."""

    conditioning: Trajectory
    logs: dict[str, Trajectory]


def plan_excitation(config: TestbedConfig, params: CatheterParams, short: bool = False,
                    fast_inputs: bool = False) -> ExcitationPlan:
    """Conditioning, "train" and "holdout" at the SYNC period, inside the workspace and the axes' limits
    (a trajectory that is not raises TrajectoryError here, before anything moves). fast_inputs: the
    steps and multisines of `fast_input_trajectories` instead of the standard excitation."""
    workspace = workspace_for(config, params)
    limits = limits_for(config)
    period_s = config.sync.period_s
    logs = (fast_input_trajectories(workspace, limits, period_s) if fast_inputs else
            {"train": training_trajectory(workspace, limits, period_s, short=short),
             "holdout": holdout_trajectory(workspace, limits, period_s, short=short)})
    return ExcitationPlan(conditioning_trajectory(workspace, limits, period_s), logs)


def record_excitation(session: Session, plan: ExcitationPlan, folder: Path, params: CatheterParams,
                      on_cycle: Callable[[str, int, int], None] | None = None, *,
                      overwrite: bool = False) -> dict[str, RunResult]:
    """Home, then for each planned log: move to its start, condition, and run and log it to
    folder/<name>.csv.

    on_cycle(name, done, total) is called after every cycle of every run (the conditioning's as
    "<name> conditioning"); overwrite replaces existing logs. Returns each log's result (cycles,
    cycles with a tip, tracker loss, log path); each log's summary holds its rows with and without a
    tip and the tracker loss, if any.
    """
    session.testbed.home()
    results = {}
    for name, trajectory in plan.logs.items():
        _run(session, plan.conditioning, None, f"{name} conditioning", on_cycle)
        recorder = ExperimentRecorder(session, Path(folder) / f"{name}.csv", params, source=f"crest excite: {name}",
                                      notes=NOTES, overwrite=overwrite)
        results[name] = _run(session, trajectory, recorder, name, on_cycle)
        recorder.close()
    return results


def _run(session: Session, trajectory: Trajectory, recorder: ExperimentRecorder | None, label: str,
         on_cycle: Callable[[str, int, int], None] | None) -> RunResult:
    """A profile-position move to the trajectory's start, then the trajectory with the cc controller."""
    testbed = session.testbed
    pulls_mm = trajectory.workspace.tendon_offset_mm * trajectory.start.bend_rad
    testbed.move_to(testbed.targets_from_pulls(float(pulls_mm[0]), float(pulls_mm[1]), trajectory.start.insertion_mm))
    controller = ConstantCurvatureController(trajectory.workspace, trajectory.limits, trajectory.period_s)
    total = len(trajectory)
    return run_with_controller(session, trajectory, controller, recorder=recorder,
                               on_cycle=None if on_cycle is None else lambda done: on_cycle(label, done, total))
