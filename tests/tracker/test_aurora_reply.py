"""The Aurora reply parser: known replies, every kind of damage, and fuzzing (never a crash, never a hang)."""

import pytest
from hypothesis import given, settings, strategies as st

from crest.tracker import aurora_reply as reply
from crest.tracker.aurora_reply import (ToolState, TrackerCrcError, TrackerErrorReply, TrackerProtocolError)
from sim_backend.tracker import aurora_protocol as sim_proto


def framed(body: bytes) -> bytes:
    return body + f"{reply.crc16(body):04X}\r".encode()


TX_VALID = b"010A+10000+00000+00000+00000+001234-000567+008001+000000000003100000001\n0000517A\r"


def test_tx_reply_fields_follow_the_ndicapi_widths():
    parsed = reply.parse_tx(TX_VALID)
    assert parsed.system_status == 0
    record = parsed.record(0x0A)
    assert record.state is ToolState.VALID
    assert record.q == (1.0, 0.0, 0.0, 0.0)
    assert record.position_mm == pytest.approx((12.34, -5.67, 80.01), abs=1e-9)
    assert record.rms_error_mm == 0.0
    assert record.port_status == 0x31
    assert record.frame == 1


def test_tx_reply_with_several_handles_and_states():
    body = (b"04"
            b"0A-07071+00000+07071+00000-001000+000250-999999+00153000000310000ABCD\n"
            b"0BMISSING000000710000ABCD\n"
            b"0CDISABLED000000010000ABCD\n"
            b"0DUNOCCUPIED\n"
            b"0A80")
    parsed = reply.parse_tx(framed(body))
    assert [r.handle for r in parsed.handles] == [0x0A, 0x0B, 0x0C, 0x0D]
    assert [r.state for r in parsed.handles] == [ToolState.VALID, ToolState.MISSING, ToolState.DISABLED,
                                               ToolState.UNOCCUPIED]
    first = parsed.handles[0]
    assert first.q == pytest.approx((-0.7071, 0.0, 0.7071, 0.0))
    assert first.position_mm == pytest.approx((-10.0, 2.5, -9999.99))
    assert first.rms_error_mm == pytest.approx(0.0153)
    assert first.frame == 0xABCD
    assert parsed.handles[1].port_status == 0x71 and parsed.handles[1].position_mm is None
    assert parsed.system_status == 0x0A80


def test_extra_data_of_other_reply_options_is_skipped_up_to_the_lf_as_ndicapi_does():
    body = b"010AMISSING0000003100000001EXTRA INFO\n0000"
    assert reply.parse_tx(framed(body)).record(0x0A).frame == 1


def test_tx_with_no_handles():
    assert reply.parse_tx(framed(b"000000")).handles == ()


def test_missing_handle_is_a_protocol_error_naming_the_handle():
    with pytest.raises(TrackerProtocolError, match="no record for port handle 0B"):
        reply.parse_tx(TX_VALID).record(0x0B)


def test_phsr_reply():
    assert reply.parse_phsr(framed(b"020A0310B001")) == (reply.PortHandle(0x0A, 0x031), reply.PortHandle(0x0B, 0x001))
    assert reply.parse_phsr(b"001414\r") == ()


def test_okay_and_error_replies():
    reply.parse_okay(b"OKAYA896\r", "INIT:")
    with pytest.raises(TrackerErrorReply, match="ERROR0C .*invalid in the current mode") as caught:
        reply.parse_okay(b"ERROR0C4E42\r", "TX:0001")
    assert caught.value.code == 0x0C
    with pytest.raises(TrackerProtocolError, match="expected OKAY"):
        reply.parse_okay(framed(b"OKAX"), "INIT:")


@pytest.mark.parametrize(("raw", "match"), [
    (b"OKAYA896", "not terminated by CR"),
    (b"", "not terminated by CR"),
    (b"A8\r", "shorter than its 4-digit CRC"),
    (b"OKAYA897\r", "CRC A897 does not match"),
    (b"OKAYXYZW\r", "not 4 hex digits"),
    (b"OK\x00YA896\r", "printable ASCII"),
    (framed(b"ERROR1"), "error code is not 2 hex digits"),
])
def test_damaged_framing_is_rejected_with_the_reason(raw, match):
    with pytest.raises(TrackerProtocolError, match=match):
        reply.parse_okay(raw, "INIT:")


def test_crc_mismatch_has_its_own_error_type():
    with pytest.raises(TrackerCrcError):
        reply.parse_tx(TX_VALID.replace(b"517A", b"517B"))


@pytest.mark.parametrize("body", [
    b"010A+10000+00000+00000+00000+01234-000567+008001+000000000003100000001\n0000",  # x has 5 digits
    b"010A+10000+00000+00000+00000 001234-000567+008001+000000000003100000001\n0000",  # sign replaced
    b"010A+10000+00000+00000+00000+001234-000567+008001+0000000000031000001\n0000",  # frame has 6 digits
    b"010AMISSING00000031\n0000",  # no frame number
    b"010AMISSING0000003100000001\n000",  # system status has 3 digits
    b"020AMISSING0000003100000001\n0000",  # count says 2, one record
    b"010AMISSING0000003100000001\n0BMISSING0000003100000001\n0000",  # count says 1, two records
    b"010AMISSING0000003100000001" b"0000",  # record not LF-terminated
    b"00XX0000",  # data after a count of 0
    b"G10AMISSING0000003100000001\n0000",  # count not hex
    b"0",
])
def test_wrong_widths_with_a_valid_crc_are_rejected(body):
    with pytest.raises(TrackerProtocolError):
        reply.parse_tx(framed(body))


@pytest.mark.parametrize("body", [b"010A03", b"020A031", b"0G0A031", b"010A031X"])
def test_phsr_with_wrong_length_or_digits_is_rejected(body):
    with pytest.raises(TrackerProtocolError):
        reply.parse_phsr(framed(body))


PARSERS = [reply.parse_tx, reply.parse_phsr, lambda raw: reply.parse_okay(raw, "INIT:")]


@pytest.mark.parametrize("parse", PARSERS)
@given(raw=st.binary(max_size=400))
def test_random_bytes_give_a_protocol_error_or_a_parse(parse, raw):
    try:
        parse(raw)
    except TrackerProtocolError:
        pass


# Bodies built from the reply alphabet and framed with a valid CRC, so fuzzing reaches the field parsers.
_alphabet = st.sampled_from(list(b"0123456789ABCDEF+-\nMISNGDABLEUOCP :\x00\x7f"))
_body = st.lists(_alphabet, max_size=200).map(bytes)


@pytest.mark.parametrize("parse", PARSERS)
@given(body=_body)
def test_crc_valid_random_bodies_give_a_protocol_error_or_a_parse(parse, body):
    try:
        parse(framed(body))
    except TrackerProtocolError:
        pass


_q = st.floats(-1.0, 1.0)
_mm = st.floats(-9999.99, 9999.99)
_records = st.lists(st.tuples(st.integers(1, 255), st.none() | st.tuples(st.tuples(_q, _q, _q, _q),
                                                                          st.tuples(_mm, _mm, _mm),
                                                                          st.floats(0.0, 9.9999)),
                              st.integers(0, 0xFFFFFFFF), st.integers(0, 0xFFFFFFFF)), max_size=4)


@settings(max_examples=200)
@given(records=_records, system_status=st.integers(0, 0xFFFF))
def test_sim_encoder_and_driver_parser_agree(records, system_status):
    """The simulator's TX encoder and the driver's parser, written apart, round-trip every field."""
    lines = [sim_proto.tx_record(handle, None if data is None else sim_proto.transform_text(*data), status, frame)
             for handle, data, status, frame in records]
    raw = sim_proto.encode_reply(sim_proto.tx_body(lines, system_status))
    parsed = reply.parse_tx(raw)
    assert parsed.system_status == system_status
    assert len(parsed.handles) == len(records)
    for (handle, data, status, frame), record in zip(records, parsed.handles):
        assert (record.handle, record.port_status, record.frame) == (handle, status, frame)
        if data is None:
            assert record.state is ToolState.MISSING and record.position_mm is None
        else:
            q, position_mm, rms = data
            assert record.q == pytest.approx(q, abs=0.5e-4 + 1e-12)
            assert record.position_mm == pytest.approx(position_mm, abs=0.5e-2 + 1e-9)
            assert record.rms_error_mm == pytest.approx(rms, abs=0.5e-4 + 1e-12)


@given(index=st.integers(0, len(TX_VALID) - 6), flip=st.integers(1, 255))
def test_any_single_byte_change_in_the_body_is_detected(index, flip):
    damaged = bytearray(TX_VALID)
    damaged[index] ^= flip
    with pytest.raises(TrackerProtocolError):
        reply.parse_tx(bytes(damaged))
