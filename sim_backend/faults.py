"""Fault injection specifications: ``AXIS:KIND@SECONDS``.

Examples: ``tendon3:emcy@2.0``, ``insertion:heartbeat@1.0``, ``tracker:disconnect@1.5``.
SECONDS is the time since the fault clock started: the virtual testbed's start, or, for a testbed
built with ``faults_wait_for_run=True`` (the crest CLI's), the moment the host starts the run's
motion (``VirtualTestbed.start_fault_clock``). Per-axis kinds (for any
axis name except ``tracker``):

    emcy          the drive faults with EMCY 0x2310 (continuous over current)
    heartbeat     the drive goes silent (no heartbeat, no frames at all)
    stall         the motor jams, so a following error (EMCY 0x8611) follows
    sdo_timeout   the drive stops answering SDO requests
    error_frames  the drive's transmissions fail with CAN error frames until it
                  is error passive (EMCY 0x8120)

Tracker kinds (axis ``tracker``, carried out by the tracker simulator):
``disconnect``, ``crc`` (corrupted reply CRC), ``missing_tool``.
"""

from __future__ import annotations

import enum
import math
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from sim_backend.sim_time import whole_us

TRACKER_AXIS = "tracker"


class FaultKind(enum.Enum):
    EMCY = "emcy"
    HEARTBEAT = "heartbeat"
    STALL = "stall"
    SDO_TIMEOUT = "sdo_timeout"
    ERROR_FRAMES = "error_frames"
    DISCONNECT = "disconnect"
    CRC = "crc"
    MISSING_TOOL = "missing_tool"


DRIVE_FAULT_KINDS = frozenset({FaultKind.EMCY, FaultKind.HEARTBEAT, FaultKind.STALL,
                               FaultKind.SDO_TIMEOUT, FaultKind.ERROR_FRAMES})
TRACKER_FAULT_KINDS = frozenset({FaultKind.DISCONNECT, FaultKind.CRC, FaultKind.MISSING_TOOL})

_SPEC = re.compile(r"^(?P<axis>[A-Za-z_][A-Za-z0-9_]*):(?P<kind>[a-z_]+)@(?P<seconds>[^@]+)$")


def _kind_names(kinds: frozenset[FaultKind]) -> str:
    return ", ".join(sorted(kind.value for kind in kinds))


@dataclass(frozen=True)
class FaultSpec:
    """One fault: which axis (or ``tracker``), what kind, when (s since start)."""

    axis: str
    kind: FaultKind
    at_s: float

    @property
    def targets_tracker(self) -> bool:
        return self.axis == TRACKER_AXIS

    def __str__(self) -> str:
        return f"{self.axis}:{self.kind.value}@{self.at_s:g}"


def check_fault_axes(faults: Iterable[FaultSpec], drive_names: Sequence[str]) -> None:
    """ValueError for a drive fault whose axis names none of the drives (tracker faults pass)."""
    for fault in faults:
        if not (fault.targets_tracker or fault.axis in drive_names):
            raise ValueError(f"fault {fault}: no drive named {fault.axis!r}; drives are {', '.join(drive_names)}")


def parse_fault(text: str) -> FaultSpec:
    """Parse ``AXIS:KIND@SECONDS``; ValueError says what is wrong and what is allowed."""
    match = _SPEC.match(text.strip())
    if match is None:
        raise ValueError(
            f"fault {text!r} is not of the form AXIS:KIND@SECONDS, e.g. tendon3:emcy@2.0 or tracker:disconnect@1.5")
    axis, kind_name, seconds_text = match["axis"], match["kind"], match["seconds"]
    try:
        kind = FaultKind(kind_name)
    except ValueError:
        raise ValueError(
            f"fault {text!r}: unknown kind {kind_name!r}; axis kinds are {_kind_names(DRIVE_FAULT_KINDS)}, "
            f"tracker kinds are {_kind_names(TRACKER_FAULT_KINDS)}") from None
    try:
        at_s = float(seconds_text)
    except ValueError:
        raise ValueError(f"fault {text!r}: time {seconds_text!r} is not a number of seconds") from None
    if not math.isfinite(at_s) or at_s < 0.0:
        raise ValueError(f"fault {text!r}: time must be a finite number of seconds >= 0, got {seconds_text!r}")
    if axis == TRACKER_AXIS and kind not in TRACKER_FAULT_KINDS:
        raise ValueError(f"fault {text!r}: the tracker takes kinds {_kind_names(TRACKER_FAULT_KINDS)}")
    if axis != TRACKER_AXIS and kind not in DRIVE_FAULT_KINDS:
        raise ValueError(f"fault {text!r}: axis {axis!r} takes kinds {_kind_names(DRIVE_FAULT_KINDS)} "
                         f"({kind.value!r} is a tracker fault: use tracker:{kind.value}@...)")
    return FaultSpec(axis=axis, kind=kind, at_s=at_s)


class FaultSchedule:
    """Faults waiting for their time; ``due(now_s)`` hands each one out once.

    A fault at ``at_s`` is due when ``now_s - clock_zero_s >= at_s`` (in whole microseconds,
    sim_backend.sim_time). The clock starts at 0 (the testbed's start) unless the schedule is
    ``held``: then nothing is due until ``start_clock(now_s)`` sets ``clock_zero_s = now_s`` (once;
    later calls keep the first zero).
    """

    def __init__(self, faults: tuple[FaultSpec, ...] | list[FaultSpec], held: bool = False) -> None:
        self._waiting = sorted(faults, key=lambda fault: fault.at_s)
        self._clock_zero_s: float | None = None if held else 0.0

    def start_clock(self, now_s: float) -> None:
        if self._clock_zero_s is None:
            self._clock_zero_s = float(now_s)

    def due(self, now_s: float) -> list[FaultSpec]:
        if self._clock_zero_s is None:
            return []
        elapsed_us = whole_us(now_s - self._clock_zero_s)
        count = 0                     # the waiting faults are sorted by time: the due ones lead
        while count < len(self._waiting) and whole_us(self._waiting[count].at_s) <= elapsed_us:
            count += 1
        ready, self._waiting = self._waiting[:count], self._waiting[count:]
        return ready

    @property
    def pending(self) -> tuple[FaultSpec, ...]:
        return tuple(self._waiting)
