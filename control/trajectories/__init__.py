"""Trajectories: validated set-points at the SYNC period (each refuses bad input before anything runs)."""
from control.trajectories.articulation_sweep import articulation_sweep
from control.trajectories.circle import circle
from control.trajectories.history_scenario import history_scenario
from control.trajectories.insertion_at_articulation import insertion_at_articulation
from control.trajectories.point_to_point import point_to_point
from control.trajectories.trajectory import Trajectory

__all__ = ["Trajectory", "articulation_sweep", "circle", "history_scenario", "insertion_at_articulation",
           "point_to_point"]
