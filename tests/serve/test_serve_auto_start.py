"""By default a real-time command starts the virtual testbed in a process of its own, other
processes reach it while the command runs, and it ends with the command, kill -9 included;
CREST_VIRTUAL_TESTBED=in-process keeps it inside the command."""
import json
import subprocess

from crest.exit_codes import ExitCode
from served_testbed import (crest_lines, relaxed_config, rows_on_disk, status_rows, stop, wait_for_rows,
                            wait_gone)
from tests.cli.cli_runner import crest, start_crest

AXES = ("tendon1", "tendon2", "tendon3", "tendon4", "insertion")


def start_own_process_run(tmp_path):
    """`crest run` with no set-up; (run, its testbed's pid, env, config, state file), returned once
    the run writes rows."""
    config = relaxed_config(tmp_path / "config")
    env = {"XDG_RUNTIME_DIR": str(tmp_path / "runtime")}
    state_file = tmp_path / "runtime" / "crest" / "testbed.json"
    log_path = tmp_path / "run.csv"
    run = start_crest("run", "builtin:circle", "--config", str(config), "--insertion-mm", "25", "--periods", "100",
                      "--record", str(log_path), env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        wait_for_rows(log_path, 20, run)
    except BaseException:
        stop(run)
        raise
    pid = json.loads(state_file.read_text())["pid"]
    return run, pid, env, config, state_file, log_path


def parent_of(pid: int) -> int:
    with open(f"/proc/{pid}/stat") as stat:
        return int(stat.read().rsplit(")", 1)[1].split()[1])


def test_status_starts_its_own_testbed_process_and_leaves_none_behind(tmp_path):
    env = {"XDG_RUNTIME_DIR": str(tmp_path / "runtime")}
    result = crest("status", "--config", str(relaxed_config(tmp_path / "config")), env=env)
    assert result.returncode == ExitCode.OK, result.stderr
    assert list(status_rows(result.stdout)) == list(AXES)
    assert not (tmp_path / "runtime" / "crest" / "testbed.json").exists()


def test_a_run_owns_its_testbed_process_which_estop_reaches_and_which_ends_with_the_run(tmp_path):
    run, pid, env, config, state_file, log_path = start_own_process_run(tmp_path)
    try:
        assert pid != run.pid and parent_of(pid) == run.pid
        estop = crest("estop", "--config", str(config), env={"XDG_RUNTIME_DIR": env["XDG_RUNTIME_DIR"]})
        _, stderr = run.communicate(timeout=120)
    finally:
        stop(run)
    assert estop.returncode == ExitCode.OK, estop.stdout + estop.stderr
    assert run.returncode == ExitCode.ERROR and "crest estop" in crest_lines(stderr)[0], stderr
    wait_gone(pid, state_file)


def test_kill_9_of_the_command_ends_its_testbed_process(tmp_path):
    run, pid, env, config, state_file, log_path = start_own_process_run(tmp_path)
    try:
        assert rows_on_disk(log_path) >= 20
        run.kill()
        run.communicate()
    finally:
        stop(run)
    wait_gone(pid, state_file)


def test_in_process_mode_keeps_the_testbed_inside_the_command_where_no_other_process_reaches_it(tmp_path):
    config = relaxed_config(tmp_path / "config")
    env = {"XDG_RUNTIME_DIR": str(tmp_path / "runtime"), "CREST_VIRTUAL_TESTBED": "in-process"}
    log_path = tmp_path / "run.csv"
    run = start_crest("run", "builtin:circle", "--config", str(config), "--insertion-mm", "25", "--periods", "100",
                      "--record", str(log_path), env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        wait_for_rows(log_path, 20, run)
        assert not (tmp_path / "runtime" / "crest" / "testbed.json").exists()
        estop = crest("estop", "--config", str(config), env={"XDG_RUNTIME_DIR": env["XDG_RUNTIME_DIR"]})
        assert estop.returncode == ExitCode.ERROR and estop.stdout == ""
        assert "no virtual testbed is running" in estop.stderr and "CREST_VIRTUAL_TESTBED=in-process" in estop.stderr
        assert run.poll() is None                       # untouched
    finally:
        stop(run)


def test_an_unknown_testbed_mode_is_refused_before_anything_starts(own_runtime_dir):
    result = crest("status", env={"CREST_VIRTUAL_TESTBED": "elsewhere"})
    assert result.returncode == ExitCode.ERROR and result.stdout == ""
    assert "CREST_VIRTUAL_TESTBED='elsewhere'" in result.stderr and "in-process, process" in result.stderr
    assert not (own_runtime_dir / "crest").exists()                 # no testbed was started
