"""A tap on the host's own connection to a served bus (Backend.tapped): it sees every frame the host
sends and receives, and the testbed keeps serving one client, not a second one for the tap."""
import time

import can

from crest.backend import Backend
from crest.testbed_service.served_bus import ServedBus
from sim_backend.bus_server import BusServer

ANSWER_TIMEOUT_S = 60.0    # a loaded 2-core machine may be slow to pass a frame between threads


class Frames(can.Listener):
    def __init__(self):
        self.ids: list[int] = []

    def on_message_received(self, msg: can.Message) -> None:
        self.ids.append(msg.arbitration_id)


def _established_connections(port: int) -> int:
    """TCP connections on 127.0.0.1 whose server side is `port` (the kernel's table, /proc/net/tcp)."""
    count = 0
    for line in open("/proc/net/tcp").read().splitlines()[1:]:
        local, state = line.split()[1], line.split()[3]
        count += int(local.split(":")[1], 16) == port and state == "01"
    return count


def test_a_tap_on_the_served_bus_sees_what_the_host_sends_and_receives_over_its_one_connection():
    channel = f"tap-test-{time.monotonic_ns()}"
    server = BusServer(channel).start()
    drive = can.Bus(interface="virtual", channel=channel)       # the testbed's side of the bus
    host = ServedBus(server.url)
    try:
        backend = Backend(bus=host, tracker_port="", served=object())
        frames = Frames()
        with backend.tapped(frames) as tapped:
            assert tapped
            host.send(can.Message(arbitration_id=0x80, data=b"", is_extended_id=False))
            sync = drive.recv(ANSWER_TIMEOUT_S)
            assert sync is not None and sync.arbitration_id == 0x80
            drive.send(can.Message(arbitration_id=0x181, data=bytes(8), is_extended_id=False))
            answer = host.recv(ANSWER_TIMEOUT_S)
            assert answer is not None and answer.arbitration_id == 0x181
            assert _established_connections(server.port) == 1
        host.send(can.Message(arbitration_id=0x80, data=b"", is_extended_id=False))   # after the block
        assert frames.ids == [0x80, 0x181]
    finally:
        host.shutdown()
        drive.shutdown()
        server.stop()
