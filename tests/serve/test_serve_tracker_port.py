"""The served testbed's tracker terminal is opened again only while that testbed lives.

Its pseudo-terminal ends with the testbed's process, and the kernel gives the lowest free number to
the next terminal opened: the next testbed's tracker. A command whose testbed was killed must not
reconnect its tracker to that number (its set-up and polls would reach the other testbed's tracker,
which then answers two clients on one line). The command asks its backend before each
reconnection (`Backend.tracker_port_alive`, the tracker driver's `port_alive`)."""
import time

from crest.backend import open_backend
from crest.config import load_testbed_config
from served_testbed import start_served_testbed, stop

LOST_TIMEOUT_S = 60.0   # for the killed server's connection to be noticed; a loaded machine is slow


def test_a_joined_testbed_tracker_port_is_alive_until_the_testbed_process_is_killed(tmp_path, monkeypatch):
    served = start_served_testbed(tmp_path)
    monkeypatch.setenv("XDG_RUNTIME_DIR", served.env["XDG_RUNTIME_DIR"])
    backend = open_backend(load_testbed_config(served.config))
    try:
        assert backend.served is not None and backend.tracker_port == served.state["tracker_port"]
        assert backend.tracker_port_alive()
        served.process.kill()                    # the drives, the plant and the tracker vanish at once
        served.process.communicate()
        deadline = time.monotonic() + LOST_TIMEOUT_S
        while backend.bus.inner.lost is None:    # the host notices on its next exchange
            assert time.monotonic() < deadline, "the killed testbed's bus still counts as connected"
            backend.bus.recv(timeout=0.1)
        assert not backend.tracker_port_alive()
    finally:
        backend.close()
        stop(served.process)
