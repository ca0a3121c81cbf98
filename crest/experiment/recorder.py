"""Recording one experiment: the crest log (CSV + sidecar) and the CAN traffic beside it.

A row's tip is the tip of a tracker frame that arrived since the row before, or empty (see
tip_feed). A row's positions and forces are the drives' answers to that row's SYNC: an axis whose
answer did not come (CycleSample.fresh False) has an empty position cell, and a tendon also an
empty force cell (`measured_answers`), never its last known values again. The log is closed
with the stop cause when a safety stop happens, so a stopped run leaves a complete, readable log;
every close adds the tip coverage (rows with and without a tip, when the tracker was lost:
tip_coverage) and, per axis, the number of rows in which the drive's answer to that SYNC did not
come, the rows with that axis' cells empty (drive_feedback_coverage), to the sidecar's summary. A
stop after the log was closed (at the end of the session) still puts its cause into the sidecar.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from crest import __version__
from crest.driver import CycleSample, SafetyStop
from crest.driver.axis_targets import AXIS_ORDER
from crest.experiment.drive_feedback_coverage import DriveFeedbackCoverage
from crest.experiment.tip_coverage import TipCoverage
from crest.log import BusRecorder, LogWriter
from crest.log.log_format import catheter_dict
from crest.session import Session
from model import CatheterParams


def measured_answers(sample: CycleSample) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """(position_mm, tension_n) in AXIS_ORDER (tendon1..tendon4, insertion), as the log holds them:
    an axis whose answer to this SYNC did not come (``fresh`` False) is NaN in both (its last known
    values are not this SYNC's measurement)."""
    def measured(values: tuple[float, ...]) -> tuple[float, ...]:
        return tuple(value if fresh else float("nan") for value, fresh in zip(values, sample.fresh, strict=True))
    return measured(sample.position_mm), measured(sample.tension_n)


class ExperimentRecorder:
    """Writes one row per SYNC cycle to `<path>.csv` and the bus to `<path>.blf`."""

    def __init__(self, session: Session, csv_path: Path, catheter: CatheterParams, *, source: str,
                 notes: str = "", tip_ref: bool = True, overwrite: bool = False):
        csv_path = Path(csv_path)
        csv_path.parent.mkdir(parents=True, exist_ok=True)
        config = session.config
        self.writer = LogWriter(
            csv_path, catheter=catheter_dict(flexible_length_mm=catheter.max_free_length_mm,
                                             tendon_offset_mm=catheter.tendon_offset_mm,
                                             outer_diameter_mm=catheter.outer_diameter_mm),
            sample_rate_hz=1.0 / config.sync.period_s, tendon_force=True, tip_ref=tip_ref,
            source=f"crest {__version__}, {'virtual testbed' if session.backend.is_virtual else 'hardware'}: {source}",
            notes=notes, config=config.as_dict(), plant=session.backend.plant, overwrite=overwrite)
        self.bus_log_path = csv_path.with_suffix(".blf")
        self.bus = BusRecorder(self.bus_log_path)
        self._host_bus = session.backend.bus
        self._host_bus.tap(self.bus.on_message_received)     # what the host sends and receives
        self.tip_coverage = TipCoverage(config.tracker.loss_timeout_s if session.tracker is not None else None)
        self.feedback_coverage = DriveFeedbackCoverage(AXIS_ORDER)
        session.testbed.on_safety_stop(self._on_safety_stop)
        self._t0_s: float | None = None
        self.closed = False

    @property
    def path(self) -> Path:
        return self.writer.path

    def write(self, sample: CycleSample, tip_mm: np.ndarray | None, tip_ref_mm: np.ndarray | None = None) -> None:
        """One row: the cycle's measurements and tip_mm, the tip of a tracker frame new since the
        last row (None when no new frame with the tool in view arrived: an empty tip)."""
        if self._t0_s is None:
            self._t0_s = sample.t_s
        t_s = sample.t_s - self._t0_s
        position_mm, tension_n = measured_answers(sample)
        self.writer.write(t_s, sample.tendon_target_mm, sample.insertion_target_mm,
                          position_mm[:4], position_mm[4], tip_mm, tendon_force_n=tension_n[:4], tip_ref_mm=tip_ref_mm)
        self.tip_coverage.add(sample.t_s, tip_mm is not None and bool(np.isfinite(tip_mm).all()))
        self.feedback_coverage.add(t_s, sample.fresh)

    def close(self, summary: dict | None = None) -> None:
        if self.closed:
            return
        self.closed = True
        self.writer.close({**self.tip_coverage.summary(), **self.feedback_coverage.summary(), **(summary or {})})
        self._host_bus.untap(self.bus.on_message_received)
        self.bus.close()

    def _on_safety_stop(self, stop: SafetyStop) -> None:
        """The stop cause into the sidecar; a stop after the log was closed (while the session is
        being closed, e.g. an SDO failure at the end) is added to its summary."""
        cause = {"stop_cause": str(stop), "exit_code": int(stop.exit_code)}
        if self.closed:
            self.writer.amend_summary(cause)
        else:
            self.close(cause)
