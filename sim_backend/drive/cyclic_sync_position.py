"""Cyclic synchronous position mode (CiA 402-2, mode 8): one set-point per SYNC.

The master writes the target position 0x607A (usually by RPDO) once per
communication cycle. The drive latches it at the SYNC, so every drive on the bus
starts the same set-point at the same instant; the demand velocity is the
set-point's difference over the cycle period 0x1006 (velocity feed-forward).

Statusword bits of this mode:
    bit 12 drive follows the command value (1 while operation is enabled in CSP)
    bit 13 following error  (set by the drive's following-error monitor)
"""

from __future__ import annotations

from sim_backend.drive.setpoint_generator import SetpointGenerator

FOLLOWS_COMMAND_BIT = 0x1000


def latch_set_point(demand: SetpointGenerator, target_counts: float, dt_s: float) -> None:
    """At a SYNC: the latched target becomes the demand for the coming cycle."""
    demand.follow(target_counts, dt_s)
