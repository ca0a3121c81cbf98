"""What the live view shows, built in the view's thread from the loop's samples.

About 10 times a second (``frame``), the state takes the samples the loop queued (SampleSlot),
keeps the newest for the screen (one per refresh: the decimation to screen rate), and reads the
tracker's newest tip. Everything the loop hands over directly (progress, the stop) is a single
attribute assignment, atomic under the GIL.
"""
from __future__ import annotations

import time
from collections import deque

import numpy as np

from crest.config import TestbedConfig
from crest.driver import AXIS_ORDER, CycleSample, SafetyStop
from crest.tracker import AuroraDriver
from crest.view.model_backbone import ModelBackbone
from crest.view.sample_slot import SampleSlot
from crest.view.view_frame import AxisRow, StopReport, ViewFrame

SCREEN_PERIOD_S = 1.0 / 10.0
"""The page's refresh. At 30 Hz a headless Chromium beside a `--fast` run on 2 cores could not draw
the frames as fast as they came: they queued in the browser, the page fell 3-5 s behind the run
and every script (an E-STOP click too) waited that long; at 10 Hz it stays within 0.4 s."""
TENSION_WINDOW_S = 10.0
TRAIL_S = 3.0


class LiveState:
    def __init__(self, config: TestbedConfig, tendon_offset_mm: float, status: str) -> None:
        self.slot = SampleSlot()
        self.max_tension_n = min(axis.max_tension_n for axis in config.tendon_axes)
        self.status = status
        self.tracker: AuroraDriver | None = None
        self.reference_mm = np.empty((0, 3))
        self.total_cycles: int | None = None
        self.done_cycles = 0
        self.stop: StopReport | None = None
        self.notes: tuple[str, ...] = ()
        self._backbone = ModelBackbone(tendon_offset_mm)
        screen_points = int(TENSION_WINDOW_S / SCREEN_PERIOD_S)
        self._tension_t_s: deque[float] = deque(maxlen=screen_points)
        self._tension_n: deque[tuple[float, ...]] = deque(maxlen=screen_points)
        self._trail: deque[np.ndarray] = deque(maxlen=int(TRAIL_S / SCREEN_PERIOD_S))
        self._tip_frame: int | None = None
        self._tip_mm: np.ndarray | None = None
        self._previous: CycleSample | None = None
        self._newest: CycleSample | None = None
        self._t0_s: float | None = None
        self._frame: ViewFrame | None = None
        self._frame_wall_s = -np.inf
        self.version = 0          # bumped by every change the loop side makes (progress, stop, notes)
        self._frame_version = -1

    # --- loop side: single assignments -----------------------------------------------------
    def follow(self, status: str, reference_mm: np.ndarray | None, total_cycles: int | None) -> None:
        self.reference_mm = np.empty((0, 3)) if reference_mm is None else np.asarray(reference_mm, dtype=float)
        self.total_cycles = total_cycles
        self.done_cycles = 0
        self.status = status
        self.version += 1

    def progress(self, done_cycles: int) -> None:
        self.done_cycles = done_cycles

    def stopped(self, stop: SafetyStop) -> None:
        into = "" if self._newest is None or self._t0_s is None else \
            f", {self._newest.t_s - self._t0_s:.2f} s after the view's first sample"
        self.stop = StopReport(str(stop), int(stop.exit_code), f"at {time.strftime('%H:%M:%S')}{into}")
        self.version += 1

    def say(self, note: str) -> None:
        self.notes = (*self.notes, note)
        self.version += 1

    # --- view side ---------------------------------------------------------------------------
    def frame(self) -> ViewFrame:
        """The screen now; rebuilt at most once per SCREEN_PERIOD_S, however many pages ask."""
        now_s = time.monotonic()
        if self._frame is not None and now_s - self._frame_wall_s < SCREEN_PERIOD_S:
            return self._frame
        self._frame_wall_s = now_s
        samples = self.slot.drain()
        tip_changed = self._read_tip()
        if not samples and not tip_changed and self._frame is not None and self.version == self._frame_version:
            return self._frame
        if samples:
            self._previous = samples[-2] if len(samples) > 1 else self._newest
            self._newest = samples[-1]
            if self._t0_s is None:
                self._t0_s = samples[0].t_s
            self._tension_t_s.append(self._newest.t_s - self._t0_s)
            self._tension_n.append(self._newest.tendon_tension_n)
        self._frame_version = self.version
        self._frame = self._build()
        return self._frame

    def _read_tip(self) -> bool:
        sample = self.tracker.latest() if self.tracker is not None else None
        if sample is None or sample.frame == self._tip_frame:
            return False
        self._tip_frame = sample.frame
        self._tip_mm = None if sample.tip_mm is None else np.asarray(sample.tip_mm, dtype=float)
        if self._tip_mm is not None:
            self._trail.append(self._tip_mm)
        return True

    def _build(self) -> ViewFrame:
        newest, previous = self._newest, self._previous
        tip = self._tip_mm
        if newest is None:
            backbone, axes, t_s = np.empty((0, 3)), (), 0.0
        else:
            backbone = self._backbone.points_mm(newest.tendon_position_mm, newest.insertion_position_mm)
            axes = tuple(AxisRow(name, newest.states[i].name.replace("_", " "), newest.position_mm[i],
                                 None if previous is None else previous.target_mm[i] - newest.position_mm[i])
                         for i, name in enumerate(AXIS_ORDER))
            t_s = newest.t_s - self._t0_s
        tip_error = None
        done = self.done_cycles
        if tip is not None and 0 < done <= len(self.reference_mm):
            tip_error = float(np.linalg.norm(tip - self.reference_mm[done - 1]))
        progress = "" if self.total_cycles is None else \
            f" - {done}/{self.total_cycles} cycles ({100.0 * done / max(self.total_cycles, 1):.0f}%)"
        return ViewFrame(
            t_s=t_s, backbone_mm=backbone, tip_mm=tip,
            trail_mm=np.array(self._trail).reshape(-1, 3), reference_mm=self.reference_mm,
            tension_t_s=np.array(self._tension_t_s), tension_n=np.array(self._tension_n).reshape(-1, 4),
            max_tension_n=self.max_tension_n, axes=axes, status=self.status + progress,
            tip_error_mm=tip_error, stop=self.stop, notes=self.notes)
