"""`crest jog` driven through a pseudo-terminal, keys and all, as an operator would."""
import os
import subprocess

import numpy as np
import pytest

from cli_runner import CREST, close_terminal, on_a_terminal, read_until
from crest.exit_codes import ExitCode
from crest.log import read_log

STARTUP_TIMEOUT_S = 300.0


def start_jog(*args: str) -> tuple[int, subprocess.Popen]:
    """`crest jog --fast ARGS` on a pseudo-terminal, as an operator runs it: (the terminal's fd, process)."""
    return on_a_terminal([*CREST, "jog", "--fast", *args])


def test_jog_moves_pitch_and_insertion_and_releases_on_quit(tmp_path):
    master, process = start_jog("--record", str(tmp_path / "jog.csv"))
    try:
        # homed at 20 mm free length; status line is up. The first run in a fresh environment compiles
        # the model kernel (numba), which on a busy 2-core machine took over 60 s.
        read_until(master, b"L  20.0 mm", timeout_s=STARTUP_TIMEOUT_S)
        os.write(master, b"sss")                              # pitch +6 deg
        read_until(master, b"pitch   +6.0 deg", timeout_s=30)
        os.write(master, b"rr")                               # 2 mm more free length
        out = read_until(master, b"L  22.0 mm", timeout_s=30)
        os.write(master, b"q")
        out += read_until(master, b"released", timeout_s=60)
        assert process.wait(timeout=60) == 0
    finally:
        close_terminal(master, process)
    log = read_log(tmp_path / "jog.csv")
    assert log.tendon_cmd_mm[-1, 0] > log.tendon_cmd_mm[-1, 2]     # tendon 1 pulled, tendon 3 paid out
    assert log.insertion_cmd_mm[-1] > log.insertion_cmd_mm[0]
    tips = log.tip_mm[log.tip_valid]          # 40 Hz tracker frames in 100 Hz rows: each frame in one row
    assert 0 < len(tips) <= log.t_s[-1] * 40.0 + 1 and not np.all(tips[1:] == tips[:-1], axis=1).any()


def test_jog_pulling_one_tendon_pays_out_its_partner_and_stops_short_of_the_tension_limit(tmp_path):
    master, process = start_jog("--record", str(tmp_path / "jog.csv"))
    try:
        read_until(master, b"L  20.0 mm", timeout_s=STARTUP_TIMEOUT_S)
        os.write(master, b"1")
        out = b""
        for _ in range(20):                  # 20 x 5 x 0.2 mm = 20 mm asked of tendon 1: far beyond 40 N
            os.write(master, b"+++++")
            out += read_until(master, b"\x1b[K", timeout_s=30)
            assert process.poll() is None, out[-400:]
        out += read_until(master, b"pulling refused", timeout_s=60)
        os.write(master, b"q")
        out += read_until(master, b"released", timeout_s=60)
        assert process.wait(timeout=60) == 0
    finally:
        close_terminal(master, process)
    assert b"tension limit: tendon1" in out
    log = read_log(tmp_path / "jog.csv")
    assert np.nanmax(log.tendon_force_n) < 40.0      # never near the safety stop (NaN: a drive did not answer)
    pulled = log.tendon_cmd_mm[-1, 0] - log.tendon_cmd_mm[0, 0]
    assert pulled > 1.0
    assert log.tendon_cmd_mm[-1, 2] - log.tendon_cmd_mm[0, 2] == pytest.approx(-pulled, abs=1e-3)   # partner paid out


def test_a_safety_stop_during_jog_starts_its_message_on_a_new_line():
    master, process = start_jog("--fault", "tendon3:emcy@8.0")
    try:
        out = read_until(master, b"L  20.0 mm", timeout_s=STARTUP_TIMEOUT_S)      # the status line is up
        out += read_until(master, b"all axes were quick-stopped", timeout_s=120)
        assert process.wait(timeout=60) == ExitCode.EMCY
    finally:
        close_terminal(master, process)
    before_stop = out[:out.index(b"crest: safety stop")]
    assert before_stop.endswith(b"\n"), before_stop[-200:]       # not appended to the status line
