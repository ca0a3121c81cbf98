"""The CAN recording is a python-can .blf/.asc file that python-can's LogReader replays frame for frame."""

import threading
import time
import uuid
from pathlib import Path

import can
import pytest

from crest.log import BusRecorder

FRAMES = [can.Message(arbitration_id=0x180 + node, data=bytes([node, 0x27, 0x00, 0x10, 0x00, 0x00]),
                      is_extended_id=False) for node in range(1, 6)]
FRAMES.append(can.Message(arbitration_id=0x080, data=b"", is_extended_id=False))  # SYNC


class _Counter(can.Listener):
    def __init__(self, wanted: int) -> None:
        self.count = 0
        self.done = threading.Event()
        self.wanted = wanted

    def on_message_received(self, msg: can.Message) -> None:
        self.count += 1
        if self.count >= self.wanted:
            self.done.set()


def _assert_replays(path: Path) -> None:
    replayed = list(can.LogReader(path))
    assert [(m.arbitration_id, bytes(m.data)) for m in replayed] == [(m.arbitration_id, bytes(m.data)) for m in FRAMES]


@pytest.mark.parametrize("suffix", [".blf", ".asc"])
def test_attached_recorder_writes_a_replayable_file(tmp_path: Path, suffix: str):
    channel = f"recorder-{uuid.uuid4().hex}-bus"  # .blf numbers channels from trailing digits: avoid them
    path = tmp_path / f"traffic{suffix}"
    with can.Bus(interface="virtual", channel=channel) as sender, can.Bus(interface="virtual", channel=channel) as bus:
        notifier = can.Notifier(bus, [], timeout=0.05)
        recorder = BusRecorder(path)
        recorder.attach(notifier)
        counter = _Counter(len(FRAMES))
        notifier.add_listener(counter)  # called after the recorder for each frame
        for frame in FRAMES:
            sender.send(frame)
        assert counter.done.wait(timeout=5.0)
        recorder.close()
        assert recorder not in notifier.listeners
        notifier.stop()
    assert recorder.frames_recorded == len(FRAMES)
    _assert_replays(path)


def test_listening_recorder_records_a_bus_of_its_own(tmp_path: Path):
    channel = f"recorder-{uuid.uuid4().hex}-bus"
    path = tmp_path / "traffic.asc"
    with can.Bus(interface="virtual", channel=channel) as sender, can.Bus(interface="virtual", channel=channel) as bus:
        with BusRecorder(path) as recorder:
            recorder.listen(bus)
            for frame in FRAMES:
                sender.send(frame)
            deadline = time.monotonic() + 5.0
            while recorder.frames_recorded < len(FRAMES) and time.monotonic() < deadline:
                time.sleep(0.005)  # waiting on a condition with a timeout
    _assert_replays(path)


def test_a_failing_writer_stops_recording_but_never_the_notifier(tmp_path: Path):
    """The notifier also feeds the driver; an exception from a listener would kill its thread."""
    channel = f"recorder-{uuid.uuid4().int % 10**12}-99999"  # too large for a .blf channel number (uint16)
    with can.Bus(interface="virtual", channel=channel) as sender, can.Bus(interface="virtual", channel=channel) as bus:
        notifier = can.Notifier(bus, [], timeout=0.05)
        recorder = BusRecorder(tmp_path / "traffic.blf")
        recorder.attach(notifier)
        counter = _Counter(len(FRAMES))
        notifier.add_listener(counter)
        with pytest.warns(RuntimeWarning, match="CAN recording stopped after 0 frames"):
            for frame in FRAMES:
                sender.send(frame)
            assert counter.done.wait(timeout=5.0)  # every frame still reached the next listener
        recorder.close()
        notifier.stop()
    assert recorder.frames_recorded == 0 and recorder.error is not None


def test_recorder_refuses_a_format_python_can_tools_would_not_replay_as_asked(tmp_path: Path):
    with pytest.raises(ValueError, match=r"\.blf or \.asc"):
        BusRecorder(tmp_path / "traffic.txt")
