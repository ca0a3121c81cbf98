"""Simulated time on the bus: CANopen TIME stamps (COB-ID 0x100) move a virtual testbed's clock.

A testbed started on TIME stamps keeps no clock of its own: its drives send heartbeats only once a
stamp has moved them to the heartbeat's time, as a master in another process moves them."""
import threading
import time
import uuid

import can
import pytest

from drive_bench import insertion_spec, tendon_spec
from sim_backend.plant import DahlPlant, PlantConfig
from sim_backend.time_stamps import (TIME_ACK_COB_ID, TIME_COB_ID, StampAnswers, time_ack_frame, time_stamp_frame,
                                     time_stamp_seconds)
from sim_backend.virtual_testbed import TrackerSettings, VirtualTestbed

TENDONS = ("tendon1", "tendon2", "tendon3", "tendon4")
NODE_IDS = (1, 2, 3, 4, 5)
WAIT_S = 30.0           # wall time for frames of a thread on a loaded machine


def test_a_time_stamp_is_the_standard_6_byte_frame_and_carries_the_time_to_the_millisecond():
    frame = time_stamp_frame(1.5)
    assert frame.arbitration_id == TIME_COB_ID == 0x100 and not frame.is_extended_id and frame.dlc == 6
    assert bytes(frame.data) == (1500).to_bytes(4, "little") + (0).to_bytes(2, "little")
    for now_s in (0.0, 0.01, 0.025, 12.345, 86_399.999, 86_400.0, 3 * 86_400 + 0.002):
        assert time_stamp_seconds(time_stamp_frame(now_s).data) == pytest.approx(now_s, abs=5e-4)
    days_and_ms = time_stamp_frame(86_400.25).data
    assert int.from_bytes(days_and_ms[4:6], "little") == 1 and int.from_bytes(days_and_ms[:4], "little") == 250


def test_a_negative_time_or_a_frame_of_another_length_is_refused():
    with pytest.raises(ValueError, match="negative"):
        time_stamp_frame(-0.01)
    with pytest.raises(ValueError, match="6 data bytes"):
        time_stamp_seconds(b"\x00\x01")


class Frames(can.Listener):
    """Every frame the master's handle receives, in order."""

    def __init__(self):
        self.received: list[can.Message] = []
        self.arrived = threading.Condition()

    def on_message_received(self, msg):
        with self.arrived:
            self.received.append(msg)
            self.arrived.notify_all()

    def heartbeat_nodes(self):
        """Nodes that sent a heartbeat (0x700 + node with an NMT state; the boot-up message is 0x00)."""
        return [m.arbitration_id - 0x700 for m in self.received if 0x701 <= m.arbitration_id <= 0x705 and m.data[0]]

    def wait_for(self, predicate, timeout_s):
        with self.arrived:
            return self.arrived.wait_for(predicate, timeout=timeout_s)


def test_a_testbed_on_time_stamps_sends_heartbeats_only_when_a_stamp_moves_it_then_answers_the_stamp():
    specs = [tendon_spec(name, node_id) for node_id, name in enumerate(TENDONS, start=1)] + [
        insertion_spec(start_position_mm=80.0)]
    channel = f"ts-{uuid.uuid4().hex}"
    testbed = VirtualTestbed(specs, channel, DahlPlant(PlantConfig()), tracker=TrackerSettings(noise_mm=0.0))
    master = can.Bus(interface="virtual", channel=channel)
    frames = Frames()
    notifier = can.Notifier(master, [frames], timeout=0.05)
    testbed.start(time_stamps=True)
    answered = lambda: [m for m in frames.received if m.arbitration_id == TIME_ACK_COB_ID]   # noqa: E731
    try:
        master.send(time_stamp_frame(0.5))     # the drives' first tick: their heartbeat clocks start
        assert frames.wait_for(lambda: answered(), WAIT_S)
        assert not frames.wait_for(frames.heartbeat_nodes, 1.0)    # a second of wall time, no stamp: none due
        master.send(time_stamp_frame(1.0))      # ten heartbeat periods later
        assert frames.wait_for(lambda: len(answered()) == 2, WAIT_S)
        with frames.arrived:
            ids = [m.arbitration_id for m in frames.received]
        # every drive's heartbeat came in before the testbed's answer to the stamp that made it due
        assert set(frames.heartbeat_nodes()) == set(NODE_IDS)
        last_heartbeat = max(i for i, cob_id in enumerate(ids) if 0x701 <= cob_id <= 0x705)
        second_answer = [i for i, cob_id in enumerate(ids) if cob_id == TIME_ACK_COB_ID][1]
        assert last_heartbeat < second_answer
        assert time_stamp_seconds(answered()[-1].data) == 1.0
    finally:
        testbed.stop()
        notifier.stop()
        master.shutdown()
    with pytest.raises(ValueError, match="one clock"):
        VirtualTestbed(specs, f"ts-{uuid.uuid4().hex}", DahlPlant(PlantConfig())).start(realtime=True, time_stamps=True)


def test_the_master_waits_for_the_answer_to_its_last_stamp_and_not_for_a_testbed_that_stopped_answering():
    answers = StampAnswers()
    assert answers.wait_for_last(0.0, gone=lambda: False)           # nothing sent yet
    answers.sent(0.02)
    threading.Timer(0.2, answers.on_frame, args=(time_ack_frame(time_stamp_frame(0.02).data),)).start()
    assert answers.wait_for_last(WAIT_S, gone=lambda: False)
    answers.sent(0.03)
    assert not answers.wait_for_last(0.3, gone=lambda: False)       # no answer: the wait runs out ...
    started = time.monotonic()
    answers.sent(0.04)
    assert not answers.wait_for_last(WAIT_S, gone=lambda: False)    # ... and later ones do not wait
    assert time.monotonic() - started < WAIT_S / 2
    answers.on_frame(time_ack_frame(time_stamp_frame(0.04).data))  # it answers again
    answers.sent(0.05)
    assert not answers.wait_for_last(WAIT_S, gone=lambda: True)     # the bus is gone: no wait
