"""`crest jog` driven through a pseudo-terminal, keys and all, as an operator would."""
import os
import pty
import select
import subprocess
import time

import numpy as np

from cli_runner import CREST, REPO
from crest.log import read_log

STARTUP_TIMEOUT_S = 300.0


def read_until(fd, needle: bytes, timeout_s: float) -> bytes:
    out = b""
    deadline = time.monotonic() + timeout_s
    while needle not in out:
        assert time.monotonic() < deadline, f"timed out waiting for {needle!r}; got {out[-400:]!r}"
        ready, _, _ = select.select([fd], [], [], 0.1)
        if ready:
            try:
                out += os.read(fd, 4096)
            except OSError:
                break
    return out


def test_jog_moves_pitch_and_insertion_and_releases_on_quit(tmp_path):
    master, slave = pty.openpty()
    process = subprocess.Popen([*CREST, "jog", "--fast", "--record", str(tmp_path / "jog.csv")], cwd=REPO,
                               stdin=slave, stdout=slave, stderr=slave, close_fds=True)
    os.close(slave)
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
        os.close(master)
        if process.poll() is None:
            process.kill()
    log = read_log(tmp_path / "jog.csv")
    assert log.tendon_cmd_mm[-1, 0] > log.tendon_cmd_mm[-1, 2]     # tendon 1 pulled, tendon 3 paid out
    assert log.insertion_cmd_mm[-1] > log.insertion_cmd_mm[0]
    tips = log.tip_mm[log.tip_valid]          # 40 Hz tracker frames in 100 Hz rows: each frame in one row
    assert 0 < len(tips) <= log.t_s[-1] * 40.0 + 1 and not np.all(tips[1:] == tips[:-1], axis=1).any()
