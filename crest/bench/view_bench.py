"""Does the live view slow the control loop? The loop's cycle time without and with it.

The same circle runs three times on the virtual testbed, through the same controller: once with no
view, once with the view's server running and no page open (its cost inside the process), once
with the live view serving a headless Chromium that draws the page at its 10 Hz (without a browser
on this machine: no page open again, and the result says so; the browser's own drawing competes
for the same CPU cores). The cycle time is the wall time between consecutive control cycles, taken in the loop's own
on_cycle callback. In simulated time (the default) the loop runs back to back, so the cycle time
is the loop's whole work per cycle (drives, plant, bus, controller) and any time the view's
thread takes from it shows in full; in real time (``realtime=True``) the loop waits for each SYNC
period, and the view would show as cycles later than the nominal period. The tracker is left
out: in simulated time its wall-clock frames would pace the loop.

With the browser, a second thread also times how long the page takes to answer a trivial script
(selenium's ``execute_script("return 1")``, every PAGE_PROBE_S during the run): the page's own
thread runs that script after whatever it has queued, so this is how late an E-STOP click would be
handled. A page that falls behind the frames sent to it answers seconds late (paint_handshake.py).
"""
from __future__ import annotations

import contextlib
import threading
import time

import numpy as np

from control import Articulation, make_controller
from crest.bench.headless_browser import browser_missing, headless_chromium
from crest.config import load_testbed_config
from crest.experiment.builtin_trajectories import BuiltinOptions, builtin_trajectory
from crest.experiment.controlled_run import run_with_controller
from crest.experiment.workspace_from_config import limits_for, workspace_for
from crest.session import SessionOptions, open_session
from crest.view.live_view import live_view
from model import CatheterParams

CIRCLE_PERIOD_S = 8.0
PAGE_SETTLE_S = 2.0          # the page's first load and render, before the measured run starts
PAGE_PROBE_S = 0.5           # between two timings of the page's answer


def control_loop_with_and_without_view(duration_s: float = 20.0, controller_name: str = "dahl", *,
                                       realtime: bool = False) -> dict:
    """``duration_s`` of circle (trajectory time) each, without and with the view."""
    missing = browser_missing()
    return {"duration_s": duration_s, "controller": controller_name,
            "clock": "real time" if realtime else "simulated time (back to back)",
            "client": "none: " + missing if missing else "headless Chromium drawing the page",
            "without_view": _cycle_times(duration_s, controller_name, realtime, view=False, browser=False),
            "with_view_no_client": _cycle_times(duration_s, controller_name, realtime, view=True, browser=False),
            "with_view": _cycle_times(duration_s, controller_name, realtime, view=True, browser=missing is None)}


def _cycle_times(duration_s: float, controller_name: str, realtime: bool, *, view: bool, browser: bool) -> dict:
    config = load_testbed_config()
    params = CatheterParams.from_toml()
    workspace, limits, period_s = workspace_for(config, params), limits_for(config), config.sync.period_s
    start = Articulation(0.0, 0.0, config.insertion_axis.home_position_mm)
    trajectory = builtin_trajectory("circle", workspace, limits,
                                    BuiltinOptions(articulation_deg=90.0, periods=max(1.0, duration_s / CIRCLE_PERIOD_S),
                                                   circle_period_s=CIRCLE_PERIOD_S), period_s, start)
    controller = make_controller(controller_name, workspace, limits, period_s)
    stamps: list[float] = []
    with contextlib.ExitStack() as stack:
        shown = stack.enter_context(live_view(view, config, params.tendon_offset_mm, "crest bench"))
        if browser:     # before the session: a user's browser is not pinned beside the testbed (cpu_split)
            driver = stack.enter_context(headless_chromium())
            driver.get(shown.server.url)
        session = stack.enter_context(open_session(SessionOptions(config=config, realtime=realtime, tracker=False)))
        shown.attach(session)
        session.testbed.home()
        if browser:
            session.testbed.hold(PAGE_SETTLE_S)
        on_cycle = shown.follow("bench circle", trajectory.tip_mm, len(trajectory),
                                lambda _done: stamps.append(time.perf_counter()))
        answers_ms: list[float] = []
        if browser:
            stack.enter_context(_timing_page_answers(driver, answers_ms))
        run_with_controller(session, trajectory, controller, on_cycle=on_cycle)
    cycle_ms = 1e3 * np.diff(stamps)
    result = {"cycles": len(stamps), "sync_period_ms": 1e3 * period_s,
              "median_ms": float(np.median(cycle_ms)), "p99_ms": float(np.percentile(cycle_ms, 99)),
              "longest_ms": float(cycle_ms.max()), "late_cycles": int(np.sum(cycle_ms > 1.5e3 * period_s))}
    if answers_ms:
        result["page_answer_ms"] = {"count": len(answers_ms), "median": float(np.median(answers_ms)),
                                    "longest": float(max(answers_ms))}
    return result


@contextlib.contextmanager
def _timing_page_answers(driver, answers_ms: list[float]):
    """Time ``execute_script("return 1")`` every PAGE_PROBE_S in a thread of its own while the block runs."""
    done = threading.Event()

    def probe() -> None:
        while not done.wait(PAGE_PROBE_S):
            start = time.perf_counter()
            driver.execute_script("return 1")
            answers_ms.append(1e3 * (time.perf_counter() - start))
    thread = threading.Thread(target=probe, name="page-probe", daemon=True)
    thread.start()
    try:
        yield
    finally:
        done.set()
        thread.join()
