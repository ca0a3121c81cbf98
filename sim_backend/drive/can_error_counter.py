"""The transmit error counter (TEC) of a CAN controller, ISO 11898-1 fault confinement.

A transmitter that detects an error sends an error frame and adds 8 to its TEC;
each successful transmission subtracts 1. At TEC >= 128 the node is error
passive (CiA 301 EMCY 0x8120), below 128 again it is error active, and at
TEC > 255 it goes bus-off. So 16 consecutive transmit errors make a node error
passive, and 128 good frames afterwards make it error active again.
"""

from __future__ import annotations

ERROR_PASSIVE_LIMIT = 128
BUS_OFF_LIMIT = 256


class CanErrorCounter:
    def __init__(self) -> None:
        self.transmit_error_count = 0

    @property
    def error_passive(self) -> bool:
        return self.transmit_error_count >= ERROR_PASSIVE_LIMIT

    def on_transmit_error(self) -> None:
        self.transmit_error_count = min(self.transmit_error_count + 8, BUS_OFF_LIMIT)

    def on_transmit_success(self) -> None:
        self.transmit_error_count = max(self.transmit_error_count - 1, 0)
