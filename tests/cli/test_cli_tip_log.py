"""What a recorded run logs as the tracker's tip: only frames that arrived, each once.

The tracker runs at 40 Hz, the log at the 100 Hz SYNC: a row carries a tip only when a new
tracker frame arrived since the row before, so about 40% of the rows do, and after the tracker is
lost none do; the run's summary line and the log's sidecar say when it was lost.
"""
import json
import re

import numpy as np

from cli_runner import crest
from crest.log import read_log
from crest.session import TRACKER_RATE_HZ

FAULT_AT_S = 1.5


def test_an_open_loop_run_that_loses_the_tracker_logs_no_tip_after_it_and_says_when(tmp_path):
    log_path = tmp_path / "run.csv"
    result = crest("run", "builtin:sweep", "--fast", "--fault", f"tracker:disconnect@{FAULT_AT_S}",
                   "--record", str(log_path))
    assert result.returncode == 0, result.stderr
    log = read_log(log_path)
    summary = json.loads(log_path.with_suffix(".json").read_text())["summary"]
    lost_at_s = summary["tracker_lost_at_s"]
    assert lost_at_s is not None and 0.0 < lost_at_s < log.t_s[-1]
    after = log.t_s > lost_at_s + 1e-9
    assert not log.tip_valid[after].any()                      # no tip is logged after the loss
    assert log.tip_valid[np.searchsorted(log.t_s, lost_at_s)]  # the loss time is the last tip's
    assert summary["rows_after_tracker_loss"] == after.sum() > 100
    assert summary["rows_with_tip_after_tracker_loss"] == 0
    assert summary["rows_with_tip"] == log.tip_valid.sum()
    assert summary["rows_without_tip"] == len(log) - log.tip_valid.sum()
    line = result.stdout.strip().splitlines()[-1]
    assert f"tracker lost at {lost_at_s:.2f} s; 0 of {after.sum()} rows after it have a tip" in line
    assert f"over {log.tip_valid.sum()} tracker samples" in line     # the tip error counts only real tips


def test_a_recorded_run_logs_each_tracker_frame_once_with_the_units_of_every_column(tmp_path):
    log_path = tmp_path / "run.csv"
    result = crest("run", "builtin:sweep", "--fast", "--record", str(log_path))
    assert result.returncode == 0, result.stderr
    log = read_log(log_path)
    has_tip = log.tip_valid
    # In simulated time the tracker's frames come exactly at its rate, 2.5 SYNC periods apart.
    assert abs(has_tip.sum() - log.t_s[-1] * TRACKER_RATE_HZ) <= 2
    assert not (has_tip[1:] & has_tip[:-1]).any()          # frames are 25 ms apart, rows 10 ms
    tips = log.tip_mm[has_tip]
    assert not np.all(tips[1:] == tips[:-1], axis=1).any()  # no frame is logged twice
    sidecar = json.loads(log_path.with_suffix(".json").read_text())
    assert sidecar["summary"]["tracker_lost_at_s"] is None
    assert sidecar["summary"]["rows_with_tip"] == has_tip.sum()
    header = log_path.read_text().splitlines()[0].split(",")
    assert list(sidecar["units"]) == header
    assert sidecar["units"] == {name: "s" if name == "t" else "N" if name.startswith("tendon_force") else "mm"
                                for name in header}
    tip_samples = int(re.search(r"over (\d+) tracker samples", result.stdout)[1])
    assert tip_samples == has_tip.sum()
