"""Frames at the pace the browser draws them: the next frame leaves only when the last one is painted.

A browser that cannot draw the live view's frames as fast as the server sends them (one every
SCREEN_PERIOD_S) queues them, and everything else the page does waits behind the queue. Measured
before this handshake (2026-11-28, 2 cores, beside a simulated-time `crest run --fast --view`), the
renderer spent its whole thread applying patches, laying out and painting (a Chrome profile: 31%
painting, 23% applying patches, 13% re-laying out the text panels); a trivial script in the page
waited 10-15 s behind the queue on an idle machine and 20-30 s on a loaded one, and so would an
E-STOP click.

Each frame carries its number and the server's send time (Unix ms) in a hidden Div (`frame_sent`,
"N T"). When the browser has applied it, it
waits for its next animation frame (the paint), then writes the number back into a second hidden
Div (`frame_painted`), which Bokeh syncs to the server. The live view sends a frame only when every
frame sent has been painted, so at most one frame is in flight: a slow browser gets fewer frames,
each of them current, and never a backlog. The page is served with a frame in it; the browser
acknowledges that one when the document is ready. A tab in the background does not paint, so the
server sends it nothing until it is shown again.
"""
from __future__ import annotations

import time

from bokeh.events import DocumentReady
from bokeh.models import CustomJS, Div

ACK_JS = """
const number = frame.text;
requestAnimationFrame(() => setTimeout(() => { if (painted.text !== number) painted.text = number; }, 0));
"""


class PaintHandshake:
    def __init__(self) -> None:
        self.frame = Div(text="0 0", visible=False, name="frame_sent")
        self.painted = Div(text="0 0", visible=False, name="frame_painted")
        self._sent = 0
        self._painted = 0
        self._ack = CustomJS(args=dict(frame=self.frame, painted=self.painted), code=ACK_JS)
        self.frame.js_on_change("text", self._ack)
        self.painted.on_change("text", self._on_painted)

    @property
    def models(self) -> list[Div]:
        """The two hidden Divs; they must be in the page's layout."""
        return [self.frame, self.painted]

    def install(self, doc) -> None:
        """Acknowledge the frame the document is served with once the browser has drawn it."""
        doc.js_on_event(DocumentReady, self._ack)

    def sent(self) -> None:
        """A frame has just been handed to Bokeh: number and time it (the last change of the frame)."""
        self._sent += 1
        self.frame.text = f"{self._sent} {1000.0 * time.time():.0f}"

    def all_painted(self) -> bool:
        return self._painted >= self._sent

    def _on_painted(self, _attr, _old, new: str) -> None:
        number = new.split(" ")[0]
        if number.isdigit():      # the page's own number; anything else is ignored
            self._painted = max(self._painted, min(int(number), self._sent))
