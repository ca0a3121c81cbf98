"""Comparing simulated times: in whole microseconds.

A simulated time is a float in seconds, and the same instant arrives as different floats: a sum of
a stepped clock's steps (0.01 + 0.01 + ... = 0.060000000000000005) inside the master's process, and
a TIME stamp's whole milliseconds (0.06) across the process boundary. A rule such as "a heartbeat
is due when 50 ms have passed" must hold at the same instant both ways, so durations are compared
after rounding to whole microseconds, far below any period on the bus:

    whole_us(d_s) = round(10^6 d_s)
"""
from __future__ import annotations


def whole_us(duration_s: float) -> int:
    """duration_s in whole microseconds."""
    return round(duration_s * 1e6)
