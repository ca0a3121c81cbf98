"""A validated trajectory: set-points at the SYNC period, refused as a whole if any sample is bad."""
from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from control.inverse_kinematics import Articulation, tendons_from_articulation, tip_from_articulation
from control.motion_limits import MotionLimits
from control.setpoint import SetPoint
from control.trajectories.validation import check_samples
from control.workspace import Workspace


class Trajectory:
    """Samples k = 0..K-1 at t_s = (k + 1) T after `start` (where the catheter rests when it begins).

    Construction checks every sample (control.trajectories.validation) and raises
    TrajectoryError before anything can run. Iterating yields SetPoint; the arrays t_s,
    bend_rad (K, 2), theta_rad, plane_rad, insertion_mm, labels are public, as are the
    constant-curvature images of every set-point: tip_mm (K, 3) and the tendon commands
    tendon_mm (K, 4), u_k = r theta cos(phi_k - plane) + pretension.
    """

    def __init__(self, bend_rad, insertion_mm, labels: list[str], start: Articulation, workspace: Workspace,
                 limits: MotionLimits, period_s: float):
        self.bend_rad = np.asarray(bend_rad, dtype=float).reshape(-1, 2)
        self.insertion_mm = np.asarray(insertion_mm, dtype=float).reshape(-1)
        self.labels = list(labels)
        self.period_s = float(period_s)
        self.start = start
        self.workspace = workspace
        self.limits = limits
        self.t_s = self.period_s * np.arange(1, len(self.insertion_mm) + 1)
        check_samples(self.t_s, self.bend_rad, self.insertion_mm, self.labels, start, workspace, limits,
                      self.period_s)
        self.theta_rad = np.hypot(self.bend_rad[:, 0], self.bend_rad[:, 1])
        self.plane_rad = np.arctan2(self.bend_rad[:, 1], self.bend_rad[:, 0])
        self.tip_mm = np.stack([tip_from_articulation(Articulation(th, pl, length), workspace.params)
                                for th, pl, length in zip(self.theta_rad, self.plane_rad, self.insertion_mm)])
        self.tendon_mm = np.stack([tendons_from_articulation(Articulation.from_bend(b, 0.0), workspace.tendon_offset_mm,
                                                             workspace.pretension_mm) for b in self.bend_rad])

    def __len__(self) -> int:
        return len(self.t_s)

    def __getitem__(self, k: int) -> SetPoint:
        return SetPoint(float(self.t_s[k]), self.tip_mm[k].copy(), float(self.theta_rad[k]),
                        float(self.plane_rad[k]), float(self.insertion_mm[k]), self.labels[k])

    def __iter__(self) -> Iterator[SetPoint]:
        return (self[k] for k in range(len(self)))

    @property
    def duration_s(self) -> float:
        return float(self.t_s[-1])

    def repeated(self, count: int) -> "Trajectory":
        """This trajectory played `count` times back to back (it must end where it starts); labels get
        the repetition number, e.g. "hold 2"."""
        labels = [f"{label} {k + 1}" for k in range(count) for label in self.labels]
        return Trajectory(np.tile(self.bend_rad, (count, 1)), np.tile(self.insertion_mm, count), labels, self.start,
                          self.workspace, self.limits, self.period_s)

    def mask(self, label: str) -> np.ndarray:
        """Boolean mask of the samples of one segment."""
        return np.array([lab == label for lab in self.labels])

    @property
    def end(self) -> Articulation:
        return Articulation.from_bend(self.bend_rad[-1], self.insertion_mm[-1])
