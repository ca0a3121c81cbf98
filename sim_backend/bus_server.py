"""The virtual testbed's CAN bus, served to other processes on 127.0.0.1 over python-can-remote.

python-can-remote (a python-can server over WebSocket) gives every client that connects its own
handle on the in-process ``virtual`` channel the drives live on. A client opens it with python-can
as it would any bus::

    can.Bus(interface="remote", channel=server.url)

and sees every frame the drives and the other clients send (not its own), so a master, ``crest
estop``, ``crest status`` and ``python -m can.logger -i remote -c URL`` can share the drives.

The server binds 127.0.0.1 only. A client that vanishes (killed, or its socket reset) ends only its
own handle: it is reported in one line on stderr, and the drives notice the silence through their
heartbeat consumers, as they would on a real bus.
"""
from __future__ import annotations

import sys
import threading

from can_remote.server import ClientRequestHandler, RemoteServer, RemoteServerProtocol
from can_remote.websocket import WebSocket, get_accept_key

LOCALHOST = "127.0.0.1"
SHUTDOWN_POLL_S = 0.1   # how often serve_forever looks for a shutdown request


class _ClientConnection(RemoteServerProtocol):
    """python-can-remote's connection to one client, which also lets go of a vanished client.

    The library's sending thread dies with a traceback when the client's socket is gone (killed
    client) and leaves the client's handle on the virtual bus open, where it would queue every
    frame of the bus for nobody, without end. Here the thread ends quietly and closes the handle.
    """

    def _send_to_client(self) -> None:
        try:
            super()._send_to_client()
        except OSError:         # the client's socket is gone; its receive side reports it
            self.running = False
            self.bus.shutdown()


class _ClientHandler(ClientRequestHandler):
    def start_websocket(self) -> None:
        """The library's WebSocket upgrade (can_remote.server), with `_ClientConnection`."""
        self.send_response(101)
        self.send_header("Upgrade", "WebSocket")
        self.send_header("Connection", "Upgrade")
        self.send_header("Sec-WebSocket-Accept", get_accept_key(self.headers["Sec-WebSocket-Key"]))
        offered = [name.strip() for name in self.headers.get("Sec-WebSocket-Protocol", "can.json.v1").split(",")]
        protocol = "can.binary+json.v1" if "can.binary+json.v1" in offered else "can.json.v1"
        self.send_header("Sec-WebSocket-Protocol", protocol)
        self.end_headers()
        connection = _ClientConnection(self.server.config, WebSocket(None, protocol, sock=self.request))
        self.server.clients.append(connection)
        try:
            connection.run()
        finally:
            self.server.clients.remove(connection)


class _LocalRemoteServer(RemoteServer):
    def __init__(self, host: str, port: int, **config) -> None:
        super().__init__(host, port, **config)
        self.RequestHandlerClass = _ClientHandler

    def handle_error(self, request, client_address) -> None:
        """A client's connection broke off (socketserver's default prints a traceback)."""
        error = sys.exc_info()[1]
        print(f"bus server: client {client_address[0]}:{client_address[1]} disconnected ({error!r})",
              file=sys.stderr, flush=True)


class BusServer:
    """Serves the virtual CAN channel ``channel`` on 127.0.0.1:``port`` (0: any free port)."""

    def __init__(self, channel: str, port: int = 0) -> None:
        self._server = _LocalRemoteServer(LOCALHOST, port, interface="virtual", channel=channel)
        self._thread: threading.Thread | None = None

    @property
    def port(self) -> int:
        return self._server.server_port

    @property
    def url(self) -> str:
        """The python-can channel of the served bus (interface "remote")."""
        return f"ws://{LOCALHOST}:{self.port}/"

    def start(self) -> BusServer:
        self._thread = threading.Thread(target=self._server.serve_forever, args=(SHUTDOWN_POLL_S,),
                                        name="bus-server", daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        """Stop accepting, close every client's connection (their python-can bus raises on the
        next receive) and release the port."""
        if self._thread is not None:
            self._server.shutdown()
            self._thread.join(timeout=2.0)
            self._thread = None
        for client in list(self._server.clients):
            client.running = False
            try:
                client.terminate(ConnectionAbortedError("the virtual testbed stopped"))
            except OSError:
                pass   # that client's socket is gone already
        self._server.server_close()
