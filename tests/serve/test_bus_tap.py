"""A tap on the host's own connection to a served bus (Backend.tapped, crest.driver.hooked_bus): it
sees every frame the host sends and receives, and the testbed keeps serving one client, not a
second one for the tap."""
import time

import can

from crest.backend import Backend
from crest.driver.hooked_bus import HookedBus
from crest.testbed_service.served_bus import ServedBus
from served_testbed import established_connections
from sim_backend.bus_server import BusServer

ANSWER_TIMEOUT_S = 60.0    # a loaded 2-core machine may be slow to pass a frame between threads


class Frames(can.Listener):
    def __init__(self):
        self.ids: list[int] = []

    def on_message_received(self, msg: can.Message) -> None:
        self.ids.append(msg.arbitration_id)


def test_a_tap_on_the_served_bus_sees_what_the_host_sends_and_receives_over_its_one_connection():
    channel = f"tap-test-{time.monotonic_ns()}"
    server = BusServer(channel).start()
    drive = can.Bus(interface="virtual", channel=channel)       # the testbed's side of the bus
    host = HookedBus(ServedBus(server.url))
    try:
        backend = Backend(bus=host, tracker_port="", served=object())
        frames = Frames()
        with backend.tapped(frames):
            host.send(can.Message(arbitration_id=0x80, data=b"", is_extended_id=False))
            sync = drive.recv(ANSWER_TIMEOUT_S)
            assert sync is not None and sync.arbitration_id == 0x80
            drive.send(can.Message(arbitration_id=0x181, data=bytes(8), is_extended_id=False))
            answer = host.recv(ANSWER_TIMEOUT_S)
            assert answer is not None and answer.arbitration_id == 0x181
            assert established_connections(server.port) == 1
        host.send(can.Message(arbitration_id=0x80, data=b"", is_extended_id=False))   # after the block
        assert frames.ids == [0x80, 0x181]
    finally:
        host.shutdown()
        drive.shutdown()
        server.stop()
