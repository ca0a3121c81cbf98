"""Ctrl-C raises KeyboardInterrupt wherever the main thread is, also in the middle of a flush;
the log the run then closes holds every row once (a row written twice, or half a row in the
middle of the file, makes the log unreadable)."""

import os
from pathlib import Path

import numpy as np
import pytest

from crest.log import LogWriter, catheter_dict, read_log

CATHETER = catheter_dict(flexible_length_mm=80.0, tendon_offset_mm=2.5, outer_diameter_mm=6.0)
ROWS = 20


def _interrupt_once(monkeypatch, name: str) -> None:
    """The next os.<name> call is interrupted: the first half of its bytes reach the file
    (os.pwrite) or the whole call completes (os.fsync), then KeyboardInterrupt."""
    real = getattr(os, name)
    armed = [True]

    def interrupted(fd, *data):
        if not armed[0]:
            return real(fd, *data)
        armed[0] = False
        if name == "pwrite":
            real(fd, data[0][: len(data[0]) // 2], data[1])
        else:
            real(fd)
        raise KeyboardInterrupt

    monkeypatch.setattr(os, name, interrupted)


@pytest.mark.parametrize("call", ["pwrite", "fsync"])
def test_an_interrupt_during_a_flush_leaves_every_row_once(tmp_path: Path, monkeypatch, call: str):
    path = tmp_path / "run.csv"
    writer = LogWriter(path, catheter=CATHETER, sample_rate_hz=100.0, source="interrupted flush")
    for row in range(ROWS):
        writer.write(row * 0.01, [row, 0, -row, 0], 50, [row, 0, -row, 0], 50, [0.0, 0.0, 80.0 - row])
    _interrupt_once(monkeypatch, call)
    with pytest.raises(KeyboardInterrupt):
        writer.flush()
    writer.write(ROWS * 0.01, [ROWS, 0, -ROWS, 0], 50, [ROWS, 0, -ROWS, 0], 50, None)
    writer.close({"stop_cause": "Ctrl-C"})
    log = read_log(path)
    np.testing.assert_array_equal(log.t_s, np.arange(ROWS + 1) * 0.01)
    np.testing.assert_array_equal(log.tendon_cmd_mm[:, 0], np.arange(ROWS + 1))
