"""Emergency (EMCY) error codes and the error register of a drive.

EMCY frame (CiA 301 section 7.2.7): COB-ID 0x80 + node id, 8 bytes:
error code (UNSIGNED16, little endian), error register 0x1001 (UNSIGNED8),
5 bytes manufacturer-specific (zero here). Code 0x0000 "error reset / no error"
is sent when the errors are cleared.

Error register 0x1001 bits: 0 generic error (set whenever any error is active),
1 current, 2 voltage, 3 temperature, 4 communication, 5 device profile specific,
7 manufacturer specific.
"""

from __future__ import annotations

#: CiA 402: continuous over current (device output side).
OVER_CURRENT = 0x2310
#: CiA 301: CAN in error passive mode.
CAN_ERROR_PASSIVE = 0x8120
#: CiA 301: life guard error or heartbeat error.
HEARTBEAT_ERROR = 0x8130
#: CiA 301: PDO not processed due to length error.
PDO_LENGTH_ERROR = 0x8210
#: CiA 402: following error.
FOLLOWING_ERROR = 0x8611
#: CiA 301: error reset or no error.
NO_ERROR = 0x0000

GENERIC = 0x01
CURRENT = 0x02
VOLTAGE = 0x04
TEMPERATURE = 0x08
COMMUNICATION = 0x10
DEVICE_PROFILE = 0x20


def register_bits(error_code: int) -> int:
    """Error register 0x1001 bits that an active error code sets (CiA 301 table 48)."""
    group = error_code & 0xF000
    bits = GENERIC
    if group == 0x2000:
        bits |= CURRENT
    elif group == 0x3000:
        bits |= VOLTAGE
    elif group == 0x4000:
        bits |= TEMPERATURE
    elif error_code & 0xFF00 in (0x8100, 0x8200):
        bits |= COMMUNICATION
    elif error_code & 0xFF00 == 0x8600:
        bits |= DEVICE_PROFILE
    return bits


class ActiveErrors:
    """Error codes currently active in the drive; ``register`` is 0x1001."""

    def __init__(self) -> None:
        self._codes: list[int] = []

    def raise_error(self, error_code: int) -> int:
        """Mark an error active; returns the error register to send with its EMCY."""
        if error_code not in self._codes:
            self._codes.append(error_code)
        return self.register

    def clear(self, error_code: int) -> int:
        """Mark one error gone; returns the remaining error register."""
        if error_code in self._codes:
            self._codes.remove(error_code)
        return self.register

    def clear_all_except(self, keep: frozenset[int]) -> int:
        """Fault reset: every error but ``keep`` (conditions still present) is gone."""
        self._codes = [code for code in self._codes if code in keep]
        return self.register

    @property
    def codes(self) -> tuple[int, ...]:
        return tuple(self._codes)

    @property
    def register(self) -> int:
        bits = 0
        for code in self._codes:
            bits |= register_bits(code)
        return bits
