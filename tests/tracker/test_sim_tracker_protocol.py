"""The simulated Aurora answers byte for byte as the NDI API specifies (CRCs computed with ndicapi's CalcCRC16)."""

import os
import select

import numpy as np
import pytest

from sim_backend.tracker import SimTracker, TrackerFault

TIP_MM = np.array([12.34, -5.67, 80.01])
# TX option 0001 for handle 0A at TIP_MM, identity rotation, port status 0x31 (occupied, initialized, enabled),
# frame 1, system status 0000, CRC 517A.
TX_FRAME_1 = (b"010A+10000+00000+00000+00000+001234-000567+008001+000000000003100000001\n0000517A\r")
OKAY = b"OKAYA896\r"


def error(code: str) -> bytes:
    crcs = {"01": "6BC2", "02": "6A82", "04": "6802", "07": "6942", "08": "6D02", "09": "ADC3",
            "0C": "4E42", "0E": "4CC2", "10": "3B02", "23": "CA42"}
    return f"ERROR{code}{crcs[code]}\r".encode()


class Line:
    """A raw client on the tracker's serial device."""

    def __init__(self, port_name: str):
        self.fd = os.open(port_name, os.O_RDWR | os.O_NOCTTY)

    def send(self, data: bytes) -> None:
        os.write(self.fd, data)

    def reply(self, timeout_s: float = 2.0) -> bytes:
        """Bytes up to and including the next CR; what arrived so far if none comes within timeout_s."""
        data = b""
        while not data.endswith(b"\r"):
            if not select.select([self.fd], [], [], timeout_s)[0]:
                return data
            data += os.read(self.fd, 1)
        return data

    def close(self) -> None:
        os.close(self.fd)


@pytest.fixture
def sim():
    tracker = SimTracker(lambda: TIP_MM, seed=1)
    yield tracker
    tracker.stop()


@pytest.fixture
def line(sim):
    sim.start()
    client = Line(sim.port_name)
    yield client
    client.close()


def setup_tracking(sim):
    for command in (b"INIT ", b"PINIT 0A", b"PENA 0AD", b"TSTART "):
        assert sim.answer(command) == OKAY, command


def test_set_up_sequence_over_the_line_is_byte_exact(line):
    exchanges = [
        (b"INIT:E3A5\r", OKAY),
        (b"COMM:500000048\r", OKAY),
        (b"PHSR:02E17E\r", b"010A001C1B5\r"),  # handle 0A occupied, not initialized
        (b"PINIT:0AD5EB\r", OKAY),
        (b"PHSR:0321BF\r", b"010A01151B4\r"),  # initialized, not enabled
        (b"PENA:0ADAD1E\r", OKAY),
        (b"PHSR:04E3FE\r", b"010A03131B5\r"),  # enabled
        (b"TSTART:5423\r", OKAY),
        (b"TX:0001031A\r", TX_FRAME_1),
        (b"TSTOP:2C14\r", OKAY),
    ]
    for command, expected in exchanges:
        line.send(command)
        assert line.reply() == expected, command


def test_command_split_across_writes_is_reassembled(line):
    line.send(b"IN")
    line.send(b"IT:E3")
    line.send(b"A5\r")
    assert line.reply() == OKAY


def test_empty_handle_list_when_nothing_matches(sim):
    sim.answer(b"INIT ")
    assert sim.answer(b"PHSR 04") == b"001414\r"


def test_missing_tool_fault_reports_missing_with_status_and_frame(sim):
    setup_tracking(sim)
    sim.inject(TrackerFault.MISSING_TOOL)
    assert sim.answer(b"TX:0001031A") == b"010AMISSING0000003100000001\n0000FE69\r"
    sim.clear("missing_tool")
    reply = sim.answer(b"TX ")
    assert reply[4:55] == TX_FRAME_1[4:55]  # the transform is back
    assert reply[63:71] == b"00000002"  # and the frame number kept counting


def test_tip_outside_the_reportable_range_is_missing_and_out_of_volume():
    tracker = SimTracker(lambda: np.array([1.0e5, 0.0, 0.0]))
    try:
        setup_tracking(tracker)
        assert tracker.answer(b"TX ") == b"010AMISSING0000007100000001\n0000FD6D\r"
    finally:
        tracker.stop()


def test_crc_fault_inverts_the_reply_crc(sim):
    sim.inject("crc")
    assert sim.answer(b"INIT ") == b"OKAY5769\r"  # 0xA896 ^ 0xFFFF
    sim.clear("crc")
    assert sim.answer(b"INIT ") == OKAY


def test_disconnect_fault_silences_the_line_until_cleared(sim, line):
    sim.inject("disconnect")
    line.send(b"INIT:E3A5\r")
    assert line.reply(timeout_s=0.3) == b""
    sim.clear("disconnect")
    line.send(b"INIT:E3A5\r")
    assert line.reply() == OKAY


@pytest.mark.parametrize(("state_commands", "command", "code"), [
    ([], b"BOGUS:ABE2", "01"),  # valid CRC, unknown command
    ([], b"INIT:E3A6", "04"),  # wrong CRC
    ([], b"INIT:", "04"),  # colon form without its CRC
    ([], b"\xffINIT ", "01"),  # not ASCII
    ([], b"init ", "01"),  # commands are upper case
    ([], b"PHSR 00", "10"),  # before INIT
    ([], b"COMM 90000", "23"),  # no baud code 9
    ([], b"COMM 5000", "07"),
    ([b"INIT "], b"PINIT 0B", "08"),  # no such port handle
    ([b"INIT "], b"PINIT 0A1", "07"),
    ([b"INIT "], b"PINIT G0", "07"),
    ([b"INIT "], b"PENA 0AD", "0E"),  # enable before initialize
    ([b"INIT ", b"PINIT 0A"], b"PENA 0AX", "09"),  # tracking priority must be S, D or B
    ([b"INIT ", b"PINIT 0A"], b"PHSR 05", "23"),
    ([b"INIT ", b"PINIT 0A", b"PENA 0AD"], b"TX ", "0C"),  # not tracking
    ([b"INIT ", b"PINIT 0A", b"PENA 0AD", b"TSTART "], b"TX 0002", "23"),  # only reply option 0001
    ([b"INIT ", b"PINIT 0A", b"PENA 0AD", b"TSTART "], b"PINIT 0A", "0C"),
    ([b"INIT ", b"PINIT 0A", b"PENA 0AD", b"TSTART "], b"TSTART ", "0C"),
])
def test_bad_command_gets_its_ndi_error_code(sim, state_commands, command, code):
    for earlier in state_commands:
        assert sim.answer(earlier) == OKAY
    assert sim.answer(command) == error(code)


def test_too_long_line_gets_error_02_and_the_line_recovers(line):
    line.send(b"X" * 1500)
    assert line.reply() == error("02")
    line.send(b"\rINIT:E3A5\r")  # the tail of the long line is a bad command of its own
    assert line.reply() == error("01")
    assert line.reply() == OKAY


def test_init_leaves_tracking_and_resets_the_handle(sim):
    setup_tracking(sim)
    assert sim.tracking
    assert sim.answer(b"INIT ") == OKAY
    assert not sim.tracking
    assert sim.answer(b"PHSR 02") == b"010A001C1B5\r"


def tx_positions_mm(tracker, count):
    positions = []
    for _ in range(count):
        reply = tracker.answer(b"TX ")
        positions.append(None if reply[4:11] == b"MISSING"
                         else [int(reply[28 + 7 * i:35 + 7 * i]) / 100 for i in range(3)])
    return positions


def test_dropout_fraction_and_noise_spread_match_their_settings():
    tracker = SimTracker(lambda: TIP_MM, noise_mm=0.5, dropout=0.25, seed=3)
    try:
        setup_tracking(tracker)
        positions = tx_positions_mm(tracker, 800)
    finally:
        tracker.stop()
    present = np.array([p for p in positions if p is not None])
    missing = len(positions) - len(present)
    assert abs(missing - 200) < 4 * np.sqrt(800 * 0.25 * 0.75)  # binomial, 4 sigma
    assert np.allclose(present.mean(axis=0), TIP_MM, atol=4 * 0.5 / np.sqrt(len(present)))
    assert np.allclose(present.std(axis=0), 0.5, rtol=0.15)


def test_same_seed_gives_the_same_reply_stream():
    streams = []
    for _ in range(2):
        tracker = SimTracker(lambda: TIP_MM, noise_mm=1.0, dropout=0.1, seed=7)
        setup_tracking(tracker)
        streams.append(tx_positions_mm(tracker, 50))
        tracker.stop()
    assert streams[0] == streams[1]


def test_keyed_frames_repeat_at_the_same_instant_and_a_repeat_shifts_no_later_frame():
    """As in simulated time: each frame's noise and dropout are those of the instant it samples,
    so the driver asking twice at one instant (a retry on a loaded machine) changes nothing after."""
    streams = []
    for repeats in ([1, 1, 1, 1, 1, 1], [1, 3, 1, 2, 1, 1]):
        instant = [0]
        tracker = SimTracker(lambda: TIP_MM, noise_mm=1.0, dropout=0.2, seed=7, draw_key=lambda: instant[0])
        setup_tracking(tracker)
        stream = []
        for count in repeats:
            instant[0] += 1
            frames = tx_positions_mm(tracker, count)
            assert all(frame == frames[0] for frame in frames)
            stream.append(frames[0])
        tracker.stop()
        streams.append(stream)
    assert streams[0] == streams[1]
    assert len({str(frame) for frame in streams[0]}) > 1      # the instants differ from one another


@pytest.mark.parametrize("kwargs", [{"noise_mm": -1.0}, {"dropout": 1.5}, {"tool_handle": 0x100}])
def test_invalid_settings_are_refused(kwargs):
    with pytest.raises(ValueError, match=next(iter(kwargs))):
        SimTracker(lambda: TIP_MM, **kwargs)
