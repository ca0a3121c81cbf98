"""The CAN recording is a python-can .blf/.asc file that python-can's LogReader replays frame for
frame: fed by the host's own handle (crest.driver.hooked_bus), it holds what the host sent, with its
direction, and what it received."""

import uuid
import warnings
from pathlib import Path

import can
import pytest

from crest.driver.hooked_bus import HookedBus
from crest.log import BusRecorder

ANSWER_TIMEOUT_S = 60.0    # a loaded 2-core machine may be slow to pass a frame between threads
SYNC = can.Message(arbitration_id=0x080, data=b"", is_extended_id=False)
ANSWERS = [can.Message(arbitration_id=0x180 + node, data=bytes([node, 0x27, 0x00, 0x10, 0x00, 0x00]),
                       is_extended_id=False) for node in range(1, 6)]


def _exchange(recorder: BusRecorder) -> None:
    """The host sends a SYNC on its hooked handle, a drive answers it five times; the recorder is
    tapped on the host's handle."""
    channel = f"recorder-{uuid.uuid4().hex}-bus"  # .blf numbers channels from trailing digits: avoid them
    with can.Bus(interface="virtual", channel=channel) as drive, \
            HookedBus(can.Bus(interface="virtual", channel=channel)) as host:
        host.tap(recorder.on_message_received)
        host.send(SYNC)
        assert drive.recv(ANSWER_TIMEOUT_S) is not None
        for answer in ANSWERS:
            drive.send(answer)
        for _ in ANSWERS:
            assert host.recv(ANSWER_TIMEOUT_S) is not None
        host.untap(recorder.on_message_received)
        host.send(SYNC)          # after the recording: not in it


@pytest.mark.parametrize("suffix", [".blf", ".asc"])
def test_a_recorder_on_the_hosts_handle_writes_what_it_sent_and_received_replayable(tmp_path: Path, suffix: str):
    path = tmp_path / f"traffic{suffix}"
    with BusRecorder(path) as recorder:
        _exchange(recorder)
    assert recorder.frames_recorded == 1 + len(ANSWERS)
    replayed = list(can.LogReader(path))
    assert [(m.arbitration_id, bytes(m.data), m.is_rx) for m in replayed] == \
        [(0x080, b"", False)] + [(m.arbitration_id, bytes(m.data), True) for m in ANSWERS]
    times_s = [m.timestamp for m in replayed]
    # the SYNC stamped when it left, on the clock of the received frames (unstamped, it would be 0 s)
    assert times_s == sorted(times_s) and times_s[-1] - times_s[0] < 2 * ANSWER_TIMEOUT_S


def test_a_failing_writer_stops_recording_and_never_the_bus(tmp_path: Path):
    """The hooks run in the threads that send and receive the frames: a writer's failure may not
    reach them."""
    channel = f"recorder-{uuid.uuid4().int % 10**12}-99999"  # too large for a .blf channel number (uint16)
    recorder = BusRecorder(tmp_path / "traffic.blf")
    with can.Bus(interface="virtual", channel=channel) as drive, \
            HookedBus(can.Bus(interface="virtual", channel=channel)) as host:
        host.tap(recorder.on_message_received)
        for answer in ANSWERS:
            drive.send(answer)
        for _ in ANSWERS:
            assert host.recv(ANSWER_TIMEOUT_S) is not None     # every frame still reached the host
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            recorder.close()
    assert recorder.frames_recorded == 0 and recorder.error is not None
    assert any("CAN recording stopped after 0 frames" in str(w.message) for w in caught)


def test_recorder_refuses_a_format_python_can_tools_would_not_replay_as_asked(tmp_path: Path):
    with pytest.raises(ValueError, match=r"\.blf or \.asc"):
        BusRecorder(tmp_path / "traffic.txt")
