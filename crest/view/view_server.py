"""The Bokeh server behind the view: 127.0.0.1 only, one signed session link, its own thread.

Bokeh serves the page and its BokehJS from the installed package (no internet needed) and keeps
each browser tab's document in sync over a websocket. The server runs with signed sessions and
without generating session ids: only the link printed by crest (its session id is signed with a
secret made for this process) opens a page; any other request, with no id or a forged one, gets
HTTP 403, and the websocket that carries the E-STOP click needs a token signed with the same
secret. The session id does not expire; the token a loaded page uses is made fresh at each load.
"""
from __future__ import annotations

import asyncio
import threading
from collections.abc import Callable

from bokeh.application import Application
from bokeh.application.handlers.function import FunctionHandler
from bokeh.document import Document
from bokeh.server.server import Server
from bokeh.util.token import generate_secret_key, generate_session_id
from tornado.ioloop import IOLoop

ADDRESS = "127.0.0.1"
START_TIMEOUT_S = 30.0
STOP_TIMEOUT_S = 10.0


class ViewServer:
    """Serves ``make_document(doc)`` for the signed link; ``start`` returns that link."""

    def __init__(self, make_document: Callable[[Document], None]) -> None:
        self._make_document = make_document
        self._secret_key = generate_secret_key().encode()
        self._session_id = generate_session_id(secret_key=self._secret_key, signed=True)
        self._ready = threading.Event()
        self._thread: threading.Thread | None = None
        self._io_loop: IOLoop | None = None
        self._server: Server | None = None
        self._error: BaseException | None = None
        self.url = ""

    def start(self) -> str:
        self._thread = threading.Thread(target=self._serve, name="crest-view", daemon=True)
        self._thread.start()
        if not self._ready.wait(START_TIMEOUT_S) or self._server is None:
            raise RuntimeError(f"the live view server did not start within {START_TIMEOUT_S:g} s"
                               + (f": {self._error}" if self._error else ""))
        self.url = f"http://{ADDRESS}:{self._server.port}/?bokeh-session-id={self._session_id}"
        return self.url

    def _serve(self) -> None:
        asyncio.set_event_loop(asyncio.new_event_loop())
        self._io_loop = IOLoop.current()
        try:
            self._server = Server({"/": Application(FunctionHandler(self._make_document))}, io_loop=self._io_loop,
                                  address=ADDRESS, port=0, allow_websocket_origin=[ADDRESS],
                                  sign_sessions=True, secret_key=self._secret_key, generate_session_ids=False)
            self._server.start()
        except Exception as error:  # reported by start() in the caller's thread
            self._error = error
            self._ready.set()
            return
        self._ready.set()
        self._io_loop.start()
        self._io_loop.close(all_fds=True)

    def stop(self) -> None:
        """Close every page's connection and end the server thread (idempotent)."""
        if self._thread is None or self._io_loop is None:
            return
        if self._server is not None:
            server, io_loop = self._server, self._io_loop

            def shut_down() -> None:
                server.stop()
                io_loop.stop()
            io_loop.add_callback(shut_down)
        self._thread.join(STOP_TIMEOUT_S)
        self._thread = None
