"""`--view`: the live view of one command's session, and its E-STOP.

    with live_view(enabled, config, tendon_offset_mm, "crest run") as view, open_session(...) as session:
        view.attach(session)                       # samples, tracker tip, stop cause, E-STOP
        on_cycle = view.follow("builtin:circle with dahl", trajectory.tip_mm, len(trajectory), progress.update)

The view is opened before the session (its link is printed while the testbed boots) and closed
after it, so the session's stop (quick stop, log saved) is never delayed by the view; the view
then keeps serving for at most LINGER_S so an open page shows how the session ended.

The E-STOP click (any page opened from the printed link) calls ``Testbed.operator_stop``: every
axis quick-stops at once, from the server's thread, and the control loop's next call finishes
the stop as for Ctrl-C (exit code INTERRUPTED) with the cause ESTOP_REASON, which the log's
sidecar records. A click during boot stops the session as soon as it is up, before any motion.
"""
from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import numpy as np

from crest.config import TestbedConfig
from crest.driver import SafetyStop, Testbed
from crest.session import Session
from crest.view.live_state import SCREEN_PERIOD_S, LiveState
from crest.view.no_view import NoView
from crest.view.page import ESTOP_REASON, Page
from crest.view.view_server import ViewServer

LINGER_S = 5.0
"""Longest the view keeps serving after the session ended, for an open page to show the end."""

FLUSH_S = 1.0
"""Time for the last frame's websocket message to reach a slow browser after it was handed to Bokeh."""


class LiveView:
    def __init__(self, config: TestbedConfig, tendon_offset_mm: float, title: str) -> None:
        self.state = LiveState(config, tendon_offset_mm, "booting the testbed")
        self._title = title
        self._extent_mm = max(axis.soft_max_mm for axis in (config.insertion_axis,))
        self._testbed: Testbed | None = None
        self._estop_pending = False
        self._ended = False
        self._pages = 0
        self._final_version: int | None = None
        self._final_shown = threading.Event()
        self.server = ViewServer(self._make_document)

    # --- the command's side --------------------------------------------------------------------
    def attach(self, session: Session) -> None:
        """Follow ``session``: every cycle's sample, the tracker's tip, the stop; arm the E-STOP."""
        self.state.tracker = session.tracker
        self.state.status = "session up"
        session.testbed.observe_cycles(self.state.slot.put)
        session.testbed.on_safety_stop(self.state.stopped)
        self._testbed = session.testbed
        if self._estop_pending:
            self._testbed.operator_stop(ESTOP_REASON)

    def follow(self, status: str, reference_mm: np.ndarray | None = None, total_cycles: int | None = None,
               then: Callable[[int], None] | None = None) -> Callable[[int], None]:
        """Show a run (its reference tip path, if any); returns the on_cycle callback for its progress."""
        self.state.follow(status, reference_mm, total_cycles)

        def on_cycle(done_cycles: int) -> None:
            self.state.progress(done_cycles)
            if then is not None:
                then(done_cycles)
        return on_cycle

    def end(self, error: BaseException | None) -> None:
        """The session is over: show how it ended, let open pages see it, stop serving."""
        self._ended = True
        if self.state.stop is None and isinstance(error, SafetyStop):
            self.state.stopped(error)
        if error is None:
            self.state.status = "session ended: every axis stopped and released"
        elif isinstance(error, (KeyboardInterrupt, SafetyStop)):
            self.state.status = "session ended by a stop"
        else:
            self.state.status = f"session ended by an error: {error}"
        self.state.version += 1
        self._final_version = self.state.version
        if self._pages:
            if self._final_shown.wait(LINGER_S):
                time.sleep(FLUSH_S)
        self.server.stop()

    # --- the server's side (its thread) ----------------------------------------------------------
    def _estop(self) -> str:
        if self._ended:
            return "E-STOP: the session has already ended; nothing is moving"
        if self._testbed is None:
            self._estop_pending = True
            self.state.say("E-STOP pressed during boot: the session stops as soon as it is up")
            return "E-STOP pressed: the session stops as soon as the testbed is up"
        self._testbed.operator_stop(ESTOP_REASON)
        self.state.say(f"E-STOP pressed at {time.strftime('%H:%M:%S')}")
        return "E-STOP sent: every axis is quick-stopping (as with Ctrl-C)"

    def _make_document(self, doc) -> None:
        page = Page(self._title, self._extent_mm, on_estop=self._estop)
        self._pages += 1

        def update() -> None:
            if not page.handshake.all_painted():     # the browser is still drawing the last frame
                return
            page.show(self.state.frame())
            if self._final_version is not None and self.state.version >= self._final_version:
                self._final_shown.set()

        doc.title = self._title
        doc.add_root(page.layout)
        page.handshake.install(doc)
        update()
        doc.add_periodic_callback(update, int(1000 * SCREEN_PERIOD_S))


@contextmanager
def live_view(enabled: bool, config: TestbedConfig, tendon_offset_mm: float, title: str) -> Iterator[LiveView | NoView]:
    """The live view when ``enabled`` (its link printed on stdout), else a NoView."""
    if not enabled:
        yield NoView()
        return
    view = LiveView(config, tendon_offset_mm, title)
    url = view.server.start()
    print(f"live view: {url}", flush=True)
    print("  (127.0.0.1 only; the link holds this session's key: only it opens the page and its E-STOP)",
          file=sys.stderr, flush=True)
    try:
        yield view
    except BaseException as error:
        view.end(error)
        raise
    view.end(None)
