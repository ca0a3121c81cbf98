"""The operator's page: Bokeh figures and widgets that draw a ViewFrame.

Panels: the backbone in three projections (side x-z, front y-z, top x-y; Bokeh draws 2D, and
three orthogonal views give every coordinate in mm at once, which a rotatable 3D scene does not);
the four tendon tensions with the max_tension_n line; one row per axis; the run's status; the
stop banner; the E-STOP button (live view) or the timeline slider (replay).
The page only draws: what to show is decided by live_state.py or replay_state.py.
"""
from __future__ import annotations

import html
import math
from collections.abc import Callable

import numpy as np
from bokeh.layouts import column, row
from bokeh.models import Button, ColumnDataSource, Div, Range1d, Slider, Span
from bokeh.plotting import figure

from crest.view.paint_handshake import PaintHandshake
from crest.view.view_frame import ViewFrame

TENDON_COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728")
PROJECTIONS = (("side", "x", "z"), ("front", "y", "z"), ("top", "x", "y"))
AXIS_INDEX = {"x": 0, "y": 1, "z": 2}
ESTOP_REASON = "E-STOP button in the live view"


class Page:
    """One browser tab's document content.

    extent_mm: half the width of the backbone plots (the longest free length).
    on_estop: live view only; called on the E-STOP click, returns the sentence to show.
    timeline_s: replay only; (start, end, on_change(t_s)) for the slider.
    """

    def __init__(self, title: str, extent_mm: float, *, on_estop: Callable[[], str] | None = None,
                 timeline_s: tuple[float, float, Callable[[float], None]] | None = None) -> None:
        self._shown: ViewFrame | None = None
        self.handshake = PaintHandshake()
        self.title = Div(text=f"<h2 style='margin:4px 0'>{html.escape(title)}</h2>", name="title")
        self.stop = Div(text="", name="stop", width=1100)
        self.status = Div(text="", name="status", width=1100)
        self.axes = Div(text="", name="axes", width=520)
        self.backbone = ColumnDataSource(dict(x=[], y=[], z=[]), name="backbone")
        self.tip = ColumnDataSource(dict(x=[], y=[], z=[]), name="tip")
        self.trail = ColumnDataSource(dict(x=[], y=[], z=[]), name="trail")
        self.reference = ColumnDataSource(dict(x=[], y=[], z=[]), name="reference")
        self.tensions = ColumnDataSource(dict(t=[], **{f"tension{k}": [] for k in range(1, 5)}), name="tensions")
        projections = [self._projection(name, h, v, extent_mm) for name, h, v in PROJECTIONS]
        self.tension_plot = figure(title="tendon tension [N]", width=560, height=300, x_axis_label="t [s]",
                                   y_axis_label="N", name="tension_plot", tools="", toolbar_location=None,
                                   y_range=Range1d(0.0, 1.0))
        for k, color in enumerate(TENDON_COLORS, start=1):
            self.tension_plot.line("t", f"tension{k}", source=self.tensions, color=color, line_width=2,
                                   legend_label=f"tendon{k}")
        self.limit = Span(location=0.0, dimension="width", line_color="red", line_dash="dashed", line_width=2)
        self.tension_plot.add_layout(self.limit)
        self.tension_plot.legend.location = "top_left"
        self.tension_plot.legend.orientation = "horizontal"
        controls = []
        if on_estop is not None:
            self.estop = Button(label="E-STOP", button_type="danger", width=220, height=60, name="estop")
            self.estop_said = Div(text="Quick-stops every axis, as Ctrl-C does.", name="estop_said", width=600)
            self.estop.on_click(lambda: self._estop_clicked(on_estop))
            controls = [row(self.estop, self.estop_said)]
        if timeline_s is not None:
            start_s, end_s, on_change = timeline_s
            self.slider = Slider(start=start_s, end=max(end_s, start_s + 1e-3), value=end_s, step=0.01,
                                 title="log time [s]", width=1100, name="timeline")
            self.slider.on_change("value_throttled", lambda _attr, _old, new: on_change(float(new)))
            controls = [self.slider]
        self.layout = column(self.title, *controls, self.stop, self.status, row(*projections),
                             row(self.tension_plot, self.axes), *self.handshake.models)

    def _projection(self, name: str, horizontal: str, vertical: str, extent_mm: float):
        plot = figure(title=f"{name} view ({horizontal}-{vertical}) [mm]", width=360, height=360, tools="",
                      x_range=Range1d(-extent_mm, extent_mm), y_range=Range1d(-extent_mm, extent_mm),
                      x_axis_label=f"{horizontal} [mm]", y_axis_label=f"{vertical} [mm]", name=f"{name}_view",
                      toolbar_location=None)
        plot.line(horizontal, vertical, source=self.reference, color="gray", line_dash="dashed",
                  legend_label="reference")
        plot.line(horizontal, vertical, source=self.trail, color="orange", line_width=2, legend_label="tip trail")
        plot.line(horizontal, vertical, source=self.backbone, color="navy", line_width=4, legend_label="model")
        plot.scatter(horizontal, vertical, source=self.tip, color="red", size=10, legend_label="tracker tip")
        plot.legend.location = "bottom_left"
        plot.legend.label_text_font_size = "8pt"
        return plot

    def _estop_clicked(self, on_estop: Callable[[], str]) -> None:
        self.estop_said.text = f"<b style='color:#b00'>{html.escape(on_estop())}</b>"

    def show(self, frame: ViewFrame) -> None:
        """Draw ``frame`` (nothing is sent when it is the frame already shown)."""
        if frame is self._shown:
            return
        self._shown = frame
        self.backbone.data = _xyz(frame.backbone_mm)
        self.tip.data = _xyz(frame.tip_mm.reshape(1, 3) if frame.tip_mm is not None else np.empty((0, 3)))
        self.trail.data = _xyz(frame.trail_mm)
        if len(self.reference.data["x"]) != len(frame.reference_mm):
            self.reference.data = _xyz(frame.reference_mm)
        self._show_tensions(frame.tension_t_s, frame.tension_n)
        self.limit.location = frame.max_tension_n
        highest_n = max(frame.max_tension_n, float(np.max(frame.tension_n, initial=0.0)))
        if np.isfinite(highest_n):
            self.tension_plot.y_range.end = 1.1 * highest_n      # the limit line stays in sight
        tip_error = "unknown" if frame.tip_error_mm is None else f"{frame.tip_error_mm:.2f} mm"
        notes = "".join(f"<br>{html.escape(note)}" for note in frame.notes)
        self.status.text = (f"<b>{html.escape(frame.status)}</b> &nbsp; t = {frame.t_s:.2f} s &nbsp; "
                            f"tip error: {tip_error} &nbsp; max_tension_n: {frame.max_tension_n:g} N{notes}")
        self.axes.text = _axis_table(frame)
        self.stop.text = "" if frame.stop is None else (
            "<div style='background:#b00;color:white;font-size:18px;padding:8px'>"
            f"{html.escape(frame.stop.describe())}</div>")
        self.handshake.sent()


    def _show_tensions(self, t_s: np.ndarray, tension_n: np.ndarray) -> None:
        """Send only the samples newer than the page has (the window rolls), else the whole window."""
        shown_t_s = self.tensions.data["t"]
        last_s = float(shown_t_s[-1]) if len(shown_t_s) else None
        if last_s is not None and len(t_s) and t_s[0] <= last_s <= t_s[-1]:
            new = t_s > last_s
            if new.any():
                self.tensions.stream(dict(t=t_s[new], **{f"tension{k + 1}": tension_n[new, k] for k in range(4)}),
                                     rollover=len(t_s))
            return
        self.tensions.data = dict(t=t_s, **{f"tension{k + 1}": tension_n[:, k] for k in range(4)})


def _xyz(points: np.ndarray) -> dict[str, np.ndarray]:
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    return {axis: points[:, index] for axis, index in AXIS_INDEX.items()}


def _position_text(position_mm: float) -> str:
    """The table's position cell: mm with 3 decimals, or "no answer" (NaN: the drive did not answer)."""
    return "no answer" if math.isnan(position_mm) else f"{position_mm:.3f}"


def _axis_table(frame: ViewFrame) -> str:
    cells = "".join(
        f"<tr><td>{html.escape(row.axis)}</td><td>{html.escape(row.state or 'not logged')}</td>"
        f"<td style='text-align:right'>{_position_text(row.position_mm)}</td><td style='text-align:right'>"
        f"{'' if row.following_error_mm is None else f'{row.following_error_mm:+.3f}'}</td></tr>"
        for row in frame.axes)
    return ("<table style='border-collapse:collapse' cellpadding='4' border='1'><tr><th>axis</th>"
            "<th>CiA 402 state</th><th>position [mm]</th><th>following error [mm]</th></tr>"
            f"{cells}</table>")
