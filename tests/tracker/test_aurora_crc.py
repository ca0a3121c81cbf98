"""The CRC-16 both tracker sides use is NDI's CalcCRC16 (ndicapi.cxx), checked on known wire strings."""

import pytest
from hypothesis import given, strategies as st

from crest.tracker import aurora_reply
from sim_backend.tracker import aurora_protocol

CRC_FUNCTIONS = [aurora_reply.crc16, aurora_protocol.crc16]

# Strings whose CRC ndicapi hard-codes on the wire (ndiSerialProbe, ndiCommandVA's reset check),
# plus the CRC-16/ARC catalogue check value.
NDICAPI_KNOWN = {b"INIT:": 0xE3A5, b"OKAY": 0xA896, b"RESET": 0xBE6F, b"VER:0": 0x65EE,
                 b"GETINFO:Features.Firmware.Version": 0x0492, b"123456789": 0xBB3D, b"": 0x0000}

_ODD_PARITY = (0, 1, 1, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 1, 1, 0)


def ndicapi_calc_crc16(data: bytes) -> int:
    """Test oracle: the CalcCRC16 macro of ndicapi.cxx, step for step (parity table, 0xC001, shifts 6 and 7)."""
    crc = 0
    for byte in data:
        value = (byte ^ (crc & 0xFF)) & 0xFF
        crc >>= 8
        if _ODD_PARITY[value & 0x0F] ^ _ODD_PARITY[value >> 4]:
            crc ^= 0xC001
        value <<= 6
        crc ^= value
        value <<= 1
        crc ^= value
        crc &= 0xFFFF  # ndicapi keeps it in an unsigned short
    return crc


@pytest.mark.parametrize("crc16", CRC_FUNCTIONS)
@pytest.mark.parametrize(("data", "expected"), NDICAPI_KNOWN.items())
def test_crc_matches_values_ndicapi_puts_on_the_wire(crc16, data, expected):
    assert crc16(data) == expected


@pytest.mark.parametrize("crc16", CRC_FUNCTIONS)
@given(data=st.binary(max_size=300))
def test_crc_equals_ndicapi_calc_crc16_on_any_bytes(crc16, data):
    assert crc16(data) == ndicapi_calc_crc16(data)


def test_commands_carry_the_crc_ndicapi_appends():
    assert aurora_reply.with_crc("INIT:") == b"INIT:E3A5\r"
    assert aurora_reply.with_crc("TX:0001") == b"TX:0001031A\r"
    assert aurora_reply.with_crc("PENA:0AD") == b"PENA:0ADAD1E\r"
