"""Below a 5 ms SYNC period an open-loop controller's commands come from a process of its own
(crest.experiment.command_process): the same commands and the same errors at the same set-point as
computed in the master, and a worker that never outlives its master, kill -9 included."""
import math
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from control import Articulation, ControlInputError, SetPoint, make_controller
from crest.config import default_config_path, load_testbed_config
from crest.experiment.builtin_trajectories import BuiltinOptions, builtin_trajectory
from crest.experiment.command_process import CommandProcess, CommandProcessError
from crest.experiment.controlled_run import run_with_controller
from crest.experiment.workspace_from_config import limits_for, workspace_for
from crest.session import SessionOptions, open_session
from model import CatheterParams
from tests.cli.cli_runner import start_crest
from tests.experiment.slow_controller import SlowConstantCurvature

CONFIG = load_testbed_config()
WORKSPACE, LIMITS = workspace_for(CONFIG, CatheterParams.from_toml()), limits_for(CONFIG)
PERIOD_S = CONFIG.sync.period_s
HOME = Articulation(0.0, 0.0, CONFIG.insertion_axis.home_position_mm)
TRAJECTORY = list(builtin_trajectory("circle", WORKSPACE, LIMITS, BuiltinOptions(articulation_deg=90.0, periods=0.25),
                                     PERIOD_S, HOME))
START_TIMEOUT_S = 120.0     # a loaded 2-core machine starting python, numpy and the model


class Targets:
    path = None

    def __init__(self):
        self.targets_mm = []

    def write(self, sample, tip_mm, tip_ref_mm=None):
        self.targets_mm.append(sample.target_mm)


def run(setpoints, command_process, controller=None):
    """The targets of each row of a run (dahl by default) in simulated time, and the error it ended
    with (or the RunResult)."""
    rows = Targets()
    controller = controller or make_controller("dahl", WORKSPACE, LIMITS, PERIOD_S)
    with open_session(SessionOptions(realtime=False, in_process=True)) as session:
        session.testbed.home()
        try:
            result = run_with_controller(session, setpoints, controller, recorder=rows,
                                         command_process=command_process)
        except ControlInputError as error:
            return rows.targets_mm, error
    return rows.targets_mm, result


def test_commands_from_another_process_are_the_ones_the_master_computes():
    in_master, result = run(TRAJECTORY, command_process=False)
    assert not result.command_process
    from_process, result = run(TRAJECTORY, command_process=True)
    assert result.command_process and result.cycles == len(TRAJECTORY)
    assert len(from_process) == len(TRAJECTORY)
    np.testing.assert_array_equal(from_process, in_master)
    assert np.ptp(np.array(from_process)[:, 0]) > 0.5      # the tendons did move


def test_a_refused_set_point_ends_the_run_at_that_set_point_as_in_the_master():
    bad = SetPoint(TRAJECTORY[5].t_s, np.array([math.nan, 0.0, 20.0]), 0.0, 0.0, 20.0)
    setpoints = [*TRAJECTORY[:5], bad, *TRAJECTORY[6:]]
    for command_process in (False, True):
        rows, error = run(setpoints, command_process)
        assert isinstance(error, ControlInputError), command_process
        assert "finite" in str(error)
        assert len(rows) == 5, command_process


def test_a_command_process_that_falls_behind_holds_the_testbed_instead_of_silencing_its_heartbeat():
    """Every 20th command takes 0.2 s, far beyond the drives' 0.25 s heartbeat patience at 100 Hz of
    simulated time once the 128 set-points ahead are used up."""
    slow = SlowConstantCurvature(WORKSPACE, LIMITS, PERIOD_S)
    from_process, result = run(TRAJECTORY, command_process=True, controller=slow)
    assert result.held_cycles > 0 and result.cycles == len(TRAJECTORY)
    in_master, _ = run(TRAJECTORY, command_process=False,
                       controller=make_controller("cc", WORKSPACE, LIMITS, PERIOD_S))
    np.testing.assert_array_equal(from_process, in_master)


def test_a_command_process_that_dies_is_named_not_waited_for():
    process = CommandProcess(make_controller("cc", WORKSPACE, LIMITS, PERIOD_S), HOME.insertion_mm)
    try:
        process.submit(TRAJECTORY[:20])
        process.next_command()
        os.kill(process.pid, signal.SIGKILL)
        # writing to the dead worker fails at once if the kernel has closed its pipe already (submit
        # raises), else the next answer it owes does: either way the error names its exit
        with pytest.raises(CommandProcessError, match="exited"):
            process.submit(TRAJECTORY[20:40])
            for _ in range(39):
                process.next_command()
    finally:
        process.close()


def test_a_controller_with_feedback_is_refused():
    with pytest.raises(ValueError, match="uses feedback"):
        CommandProcess(make_controller("dahl+fb", WORKSPACE, LIMITS, PERIOD_S), HOME.insertion_mm)


def realtime_permitted(priority: int) -> bool:
    probe = f"import os; os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param({priority}))"
    return subprocess.run([sys.executable, "-c", probe], capture_output=True).returncode == 0


def config_at_500_hz_realtime(folder: Path) -> Path:
    """configs/testbed.toml with a 2 ms SYNC period and the threads at SCHED_FIFO priority 20."""
    source = default_config_path()
    text = source.read_text()
    for key, value in (("period_s", "0.002"), ("realtime_priority", "20")):
        text, count = re.subn(rf"^{key} = \S+", f"{key} = {value}", text, flags=re.MULTILINE)
        assert count == 1
    (folder / "crest_drive.eds").write_bytes((source.parent / "crest_drive.eds").read_bytes())
    path = folder / "testbed.toml"
    path.write_text(text)
    return path


def command_workers_of(pid: int) -> list[int]:
    """The running command workers whose parent is `pid`."""
    workers = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
                cmdline = (entry / "cmdline").read_bytes()
            except OSError:
                continue
            if b"crest.experiment.command_worker" in cmdline and int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                workers.append(int(entry.name))
    return workers


def running(pid: int) -> bool:
    """Whether `pid` exists and is not a zombie (an exited child nobody has reaped yet)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


@pytest.mark.skipif(not sys.platform.startswith("linux") or not realtime_permitted(20),
                    reason="reads /proc; the command process is the default for a real-time master only")
def test_the_command_process_of_a_500_hz_run_ends_with_a_master_killed_with_kill_9(tmp_path):
    log_path = tmp_path / "run.csv"
    master = start_crest("run", "--config", str(config_at_500_hz_realtime(tmp_path)), "builtin:circle",
                         "--controller", "dahl", "--periods", "100", "--record", str(log_path),
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + START_TIMEOUT_S
        while not log_path.exists() or log_path.read_bytes().count(b"\n") < 51:
            assert time.monotonic() < deadline and master.poll() is None, master.stderr.read().decode()[-2000:]
            time.sleep(0.1)
        workers = command_workers_of(master.pid)
        assert len(workers) == 1
        master.kill()
        master.wait(timeout=30)
        deadline = time.monotonic() + 60.0
        while running(workers[0]):
            assert time.monotonic() < deadline, "the command worker outlived its master"
            time.sleep(0.1)
    finally:
        if master.poll() is None:
            master.kill()
            master.wait()
        master.stderr.close()
