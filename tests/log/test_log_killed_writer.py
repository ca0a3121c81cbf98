"""A writer killed with SIGKILL mid-run leaves a readable log missing at most the last 0.5 s."""

import os
import signal
import subprocess
import sys
import textwrap
import warnings
from pathlib import Path

import numpy as np

from crest.log import TruncatedLogWarning, read_log

PERIOD_S = 0.01
CHILD = textwrap.dedent("""
    import sys
    from crest.log import LogWriter, catheter_dict
    writer = LogWriter(sys.argv[1], sample_rate_hz=100.0, source="killed writer",
                       catheter=catheter_dict(flexible_length_mm=80, tendon_offset_mm=2.5, outer_diameter_mm=6))
    row = 0
    while True:  # runs until killed, as a control loop would
        writer.write(row * 0.01, [row * 1e-3, 0, -row * 1e-3, 0], 50, [0, 0, 0, 0], 50, [0, 0, 80])
        if row % 25 == 0:
            print(row, flush=True)
        row += 1
""")


def test_sigkill_leaves_every_row_older_than_the_flush_interval(tmp_path: Path):
    path = tmp_path / "killed.csv"
    child = subprocess.Popen([sys.executable, "-c", CHILD, str(path)], stdout=subprocess.PIPE, text=True)
    try:
        reported_row = -1
        while reported_row < 400:  # the child has written at least 4 s of log
            line = child.stdout.readline()
            assert line, f"the writer exited early with code {child.poll()}"
            reported_row = int(line)
        os.kill(child.pid, signal.SIGKILL)
    finally:
        child.kill()
        child.wait(timeout=10)
        child.stdout.close()
    assert child.returncode == -signal.SIGKILL

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TruncatedLogWarning)  # a partial last line is allowed
        log = read_log(path)
    rows = len(log)
    assert np.allclose(log.t_s, np.arange(rows) * PERIOD_S)  # a gap-free prefix of what was written
    assert log.t_s[-1] > reported_row * PERIOD_S - 0.5
    assert "summary" not in log.sidecar  # it never closed
