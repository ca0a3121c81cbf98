"""`crest view LOG.csv` in a real browser: a recorded log's last state and its stop cause.

The log is written with the writer `crest run --record` uses; its last row bends the catheter
in the x-z plane, so the model's backbone tip on the page must sit where constant curvature
puts it. Skipped with the reason when no headless Chromium or selenium is installed.
"""
from __future__ import annotations

import math
import re
import signal
import subprocess
import threading

import pytest

from crest.bench.headless_browser import browser_missing, headless_chromium
from crest.config import load_testbed_config
from crest.log import LogWriter
from crest.log.log_format import catheter_dict
from tests.cli.cli_runner import start_crest
from tests.view.page_reading import source_data, visible_text, wait_for

pytestmark = pytest.mark.skipif(browser_missing() is not None, reason=str(browser_missing()))

TENDON_OFFSET_MM = 2.5
ROWS = 200
LAST_PULL_MM = 3.0            # tendon 1 pulled, tendon 3 let out: a bend toward +x
LAST_FREE_LENGTH_MM = 60.0
STOP_LINE = ("safety stop (TENSION_LIMIT): tendon1: tension 41.2 N exceeds max_tension_n 40 N; "
             "all axes were quick-stopped")


def write_stopped_log(path):
    writer = LogWriter(path, catheter=catheter_dict(flexible_length_mm=100.0, tendon_offset_mm=TENDON_OFFSET_MM,
                                                    outer_diameter_mm=6.0),
                       sample_rate_hz=100.0, source="crest run builtin:sweep (replay test)", tendon_force=True,
                       tip_ref=True, config=load_testbed_config().as_dict())
    for i in range(ROWS):
        pull_mm = LAST_PULL_MM * i / (ROWS - 1)
        tendons = (pull_mm, 0.0, -pull_mm, 0.0)
        tensions = (5.0 + 36.2 * i / (ROWS - 1), 5.0, 5.0, 5.0)
        writer.write(0.01 * i, tendons, LAST_FREE_LENGTH_MM, tendons, LAST_FREE_LENGTH_MM, (1.0, 0.0, 59.0),
                     tendon_force_n=tensions, tip_ref_mm=(1.0, 0.0, 60.0))
    writer.close({"stop_cause": STOP_LINE, "exit_code": 13})


def test_replay_shows_the_logs_last_state_and_its_stop_cause(tmp_path):
    log_path = tmp_path / "stopped.csv"
    write_stopped_log(log_path)
    process = start_crest("view", str(log_path), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    lines: list[str] = []

    def read() -> None:
        for line in process.stdout:
            lines.append(line)
    threading.Thread(target=read, daemon=True).start()
    try:
        def printed_url():
            assert process.poll() is None, f"crest view ended early: {process.stderr.read()}"
            return next((m.group(1) for line in list(lines) if (m := re.search(r"(http://127\.0\.0\.1:\S+)", line))),
                        None)
        url = wait_for(printed_url, 120.0, "the printed replay link")
        with headless_chromium() as browser:
            browser.get(url)
            text = wait_for(lambda: (t := visible_text(browser)) and "STOPPED" in t and t, 120.0, "the stop banner")
            assert STOP_LINE in text and "exit code 13" in text
            assert f"row {ROWS} of {ROWS}" in text
            assert "not logged" in text                     # the log has no CiA 402 states
            backbone = source_data(browser, "backbone")
            theta = LAST_PULL_MM / TENDON_OFFSET_MM          # ((u1 - u3)/2)/r, constant curvature
            expected_x = LAST_FREE_LENGTH_MM * (1 - math.cos(theta)) / theta
            expected_z = LAST_FREE_LENGTH_MM * math.sin(theta) / theta
            assert backbone["x"][-1] == pytest.approx(expected_x, abs=1e-6)
            assert backbone["z"][-1] == pytest.approx(expected_z, abs=1e-6)
            assert backbone["y"][-1] == pytest.approx(0.0, abs=1e-9)
            tensions = source_data(browser, "tensions")
            assert tensions["tension1"][-1] == pytest.approx(41.2)
            assert "tip error: 1.00 mm" in text              # |(1, 0, 59) - (1, 0, 60)|
    finally:
        process.send_signal(signal.SIGINT)
        try:
            assert process.wait(60) == 0
        finally:
            if process.poll() is None:
                process.kill()
                process.wait()
    assert "replay ended" in "".join(lines)
