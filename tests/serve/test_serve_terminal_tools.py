"""Terminal programs on a served virtual testbed, through a pseudo-terminal as a user runs them:
python-can's `can.viewer` watching a run's bus, and `crest jog` driving the served drives.

The served testbed, every run and every tool are processes of their own (see served_testbed).
"""
import os
import re
import sys

from crest.exit_codes import ExitCode
from crest.log import read_log
from served_testbed import crest_lines, start_run, start_served_testbed, status_rows, stop
from tests.cli.cli_runner import CREST, close_terminal, on_a_terminal, read_until

AXES = ("tendon1", "tendon2", "tendon3", "tendon4", "insertion")
NODE_IDS = (1, 2, 3, 4, 5)
STARTUP_TIMEOUT_S = 300.0      # a fresh checkout compiles the model kernel first


def test_can_viewer_shows_the_sync_and_every_drives_pdos_of_a_run_and_quits_on_q(tmp_path):
    served = start_served_testbed(tmp_path / "served")
    run = None
    try:
        run = start_run(served, tmp_path / "run.csv")
        master, viewer = on_a_terminal([sys.executable, "-m", "can.viewer", "-i", "remote",
                                        "-c", served.state["bus_channel"]], served.env)
        try:
            screen = b""
            wanted = {0x80, *(0x180 + n for n in NODE_IDS), *(0x200 + n for n in NODE_IDS)}
            seen: set[int] = set()
            while not wanted <= seen:       # can.viewer draws each ID once, as 0x080, then updates its row
                screen += read_until(master, b"0x", timeout_s=120)
                seen = {int(found, 16) for found in re.findall(rb"0x([0-9A-F]{3})\b", screen)}
            os.write(master, b"q")
            assert viewer.wait(timeout=60) == 0
        finally:
            close_terminal(master, viewer)
        assert run.poll() is None, "the viewer must not disturb the run"
    finally:
        for process in (run, served.process):
            if process is not None:
                stop(process)


def test_jog_drives_the_served_testbed_and_releases_it_on_quit(tmp_path):
    served = start_served_testbed(tmp_path / "served")
    try:
        log_path = tmp_path / "jog.csv"
        master, jog = on_a_terminal([*CREST, "jog", "--config", str(served.config), "--record", str(log_path)],
                                    served.env)
        try:
            read_until(master, b"L  20.0 mm", timeout_s=STARTUP_TIMEOUT_S)     # homed at 20 mm free length
            os.write(master, b"sss")                                         # pitch +6 deg
            read_until(master, b"pitch   +6.0 deg", timeout_s=60)
            status = served.crest("status", "--config", str(served.config))  # the jog's drives, from outside
            assert status.returncode == ExitCode.OK, crest_lines(status.stderr)
            states = status_rows(status.stdout)
            assert list(states) == list(AXES)
            assert all(fields[1:3] == ["OPERATIONAL", "OPERATION_ENABLED"] for fields in states.values()), status.stdout
            os.write(master, b"q")
            out = read_until(master, b"released", timeout_s=120)
            assert jog.wait(timeout=120) == ExitCode.OK, out[-2000:]
        finally:
            close_terminal(master, jog)
        log = read_log(log_path)
        assert log.tendon_cmd_mm[-1, 0] > log.tendon_cmd_mm[-1, 2]      # tendon 1 pulled, tendon 3 paid out
        assert served.process.poll() is None, "the served testbed outlives the jog"
    finally:
        stop(served.process)
