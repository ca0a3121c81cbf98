"""Simulated CiA 402 servo amplifiers."""

from sim_backend.drive.cia402_state_machine import DriveState
from sim_backend.drive.drive_spec import DriveSpec
from sim_backend.drive.sim_drive import SimDrive

__all__ = ["DriveSpec", "DriveState", "SimDrive"]
