"""A recorded log as view frames: the screen at any time of the log, for `crest view LOG.csv`.

The log holds what was measured (set-points, positions, tensions, tip) but not the CiA 402
states, so the axis table says "not logged" there. A row without an axis' position (its drive did
not answer that SYNC: an empty cell) shows no position for that axis in the table; the backbone,
which the model draws from all five positions, uses that axis' position filled from its measured
rows (`missing_positions.filled_positions_mm`). The stop, if the run ended in one, comes from
the sidecar's summary (``stop_cause``, ``exit_code``) and is shown at the log's last row.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from crest.driver import AXIS_ORDER
from crest.log.log_reader import ExperimentLog, read_log
from crest.log.missing_positions import filled_positions_mm
from crest.view.model_backbone import ModelBackbone
from crest.view.view_frame import AxisRow, StopReport, ViewFrame

TENSION_WINDOW_S = 10.0
TENSION_POINTS = 300          # what a 560-pixel plot can show
TRAIL_S = 3.0


class ReplayState:
    def __init__(self, path: Path | str) -> None:
        self.log: ExperimentLog = read_log(path)
        if len(self.log) == 0:
            raise ValueError(f"{path}: the log has no rows to replay")
        self._backbone = ModelBackbone(float(self.log.catheter["tendon_offset_mm"]))
        axes = {axis["name"]: axis for axis in (self.log.sidecar.get("config") or {}).get("axes", [])
                if isinstance(axis, dict) and "name" in axis}
        limits = [axes[name]["max_tension_n"] for name in AXIS_ORDER[:4] if "max_tension_n" in axes.get(name, {})]
        self.max_tension_n = float(min(limits)) if limits else float("nan")
        self.extent_mm = float(self.log.catheter.get("flexible_length_mm", np.nanmax(self.log.insertion_pos_mm)))
        self._positions = np.column_stack([self.log.tendon_pos_mm, self.log.insertion_pos_mm])
        self._backbone_tendon_mm, self._backbone_insertion_mm = filled_positions_mm(self.log)
        self._commands = np.column_stack([self.log.tendon_cmd_mm, self.log.insertion_cmd_mm])
        valid_ref = self.log.tip_ref_mm is not None
        self._reference = self.log.tip_ref_mm[np.all(np.isfinite(self.log.tip_ref_mm), axis=1)] if valid_ref \
            else np.empty((0, 3))
        self.stop = self._stop_report()

    @property
    def start_s(self) -> float:
        return float(self.log.t_s[0])

    @property
    def end_s(self) -> float:
        return float(self.log.t_s[-1])

    def _stop_report(self) -> StopReport | None:
        summary = self.log.sidecar.get("summary") or {}
        if "stop_cause" not in summary:
            return None
        closed = f", log closed {summary['closed_utc']}" if "closed_utc" in summary else ""
        return StopReport(str(summary["stop_cause"]), int(summary.get("exit_code", -1)),
                          f"at t = {self.end_s:.2f} s (the log's last row{closed})")

    def frame_at(self, t_s: float) -> ViewFrame:
        """The screen at log time ``t_s``: the last row at or before it."""
        log = self.log
        i = max(int(np.searchsorted(log.t_s, t_s, side="right")) - 1, 0)
        tip = log.tip_mm[i] if np.all(np.isfinite(log.tip_mm[i])) else None
        recent = (log.t_s > log.t_s[i] - TRAIL_S) & (log.t_s <= log.t_s[i]) & log.tip_valid
        window = np.flatnonzero((log.t_s > log.t_s[i] - TENSION_WINDOW_S) & (log.t_s <= log.t_s[i]))
        window = np.unique(np.append(window[::max(1, len(window) // TENSION_POINTS)], i))   # the row shown last
        tensions = log.tendon_force_n[window] if log.tendon_force_n is not None else np.empty((0, 4))
        tip_error = None
        if tip is not None and log.tip_ref_mm is not None and np.all(np.isfinite(log.tip_ref_mm[i])):
            tip_error = float(np.linalg.norm(tip - log.tip_ref_mm[i]))
        axes = tuple(AxisRow(name, "", float(self._positions[i, k]),
                             float(self._commands[i - 1, k] - self._positions[i, k])
                             if i > 0 and np.isfinite(self._positions[i, k]) else None)
                     for k, name in enumerate(AXIS_ORDER))
        notes = () if log.tendon_force_n is not None else ("this log has no tendon tension columns",)
        return ViewFrame(
            t_s=float(log.t_s[i]),
            backbone_mm=self._backbone.points_mm(self._backbone_tendon_mm[i], self._backbone_insertion_mm[i]),
            tip_mm=tip, trail_mm=log.tip_mm[recent], reference_mm=self._reference,
            tension_t_s=log.t_s[window] if log.tendon_force_n is not None else np.empty(0),
            tension_n=tensions, max_tension_n=self.max_tension_n, axes=axes,
            status=f"replay of {log.path.name} ({log.source}): row {i + 1} of {len(log)}",
            tip_error_mm=tip_error, stop=self.stop if i == len(log) - 1 else None, notes=notes)
