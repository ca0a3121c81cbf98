"""`crest view LOG.csv`: the live view's panels over a recorded log, scrubbed on a timeline.

The page opens at the log's last row (where a stopped run shows its stop cause); the slider
moves through the log. There is nothing to stop, so there is no E-STOP button.
"""
from __future__ import annotations

from pathlib import Path

from crest.view.page import Page
from crest.view.replay_state import ReplayState
from crest.view.view_server import ViewServer


class ReplayView:
    def __init__(self, path: Path | str) -> None:
        self.state = ReplayState(path)
        self.server = ViewServer(self._make_document)

    def _make_document(self, doc) -> None:
        state = self.state
        page: Page | None = None

        def scrub(t_s: float) -> None:
            page.show(state.frame_at(t_s))

        page = Page(f"crest view {state.log.path.name}", state.extent_mm,
                    timeline_s=(state.start_s, state.end_s, scrub))
        page.show(state.frame_at(state.end_s))
        doc.title = f"crest view {state.log.path.name}"
        doc.add_root(page.layout)
