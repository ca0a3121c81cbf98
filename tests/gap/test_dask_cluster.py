"""The gap diagnosis on a Dask cluster (issue 17, item 4): the fits run on a LocalCluster on 127.0.0.1 and
give the same diagnosis as local processes; `crest gap --scheduler` works end to end (with `--effects`), refuses an address
where no scheduler answers before any work, and Ctrl-C during a cluster-run blind benchmark stops it with
one line and leaves no task on the cluster. Every cluster is started and stopped here."""
import dataclasses
import json
import signal
import socket
import subprocess
import time

import pytest
from distributed import Client, LocalCluster

from crest.exit_codes import ExitCode
from crest.gap.fit_executor import dask_executor
from crest.gap.log_diagnosis import diagnose_logs
from tests.cli.cli_runner import crest, start_crest
from tests.gap.conftest import TEST_SETTINGS, record_case

# few candidates, so that four diagnoses fit the test budget
SETTINGS = dataclasses.replace(TEST_SETTINGS, effects=("backlash", "tracker_offset", "gravity"))


@pytest.fixture(scope="module")
def cluster():
    with LocalCluster(host="127.0.0.1", n_workers=2, processes=True, threads_per_worker=1,
                      dashboard_address=None) as local_cluster, \
            Client(local_cluster.scheduler_address, set_as_default=False) as client:
        yield local_cluster.scheduler_address, client


def without_clock(tree):
    """The result with every wall-clock time removed: the rest must not depend on where the fits ran."""
    if isinstance(tree, dict):
        return {k: without_clock(v) for k, v in tree.items() if k not in ("seconds", "timing_s")}
    if isinstance(tree, list):
        return [without_clock(v) for v in tree]
    return tree


def cluster_idle(client: Client) -> bool:
    """No task known to the scheduler, none processing, none executing on a worker."""
    tasks = client.run_on_scheduler(lambda dask_scheduler: len(dask_scheduler.tasks))
    processing = sum(len(keys) for keys in client.processing().values())
    executing = sum(client.run(lambda dask_worker: len(dask_worker.state.executing)).values())
    return tasks == 0 and processing == 0 and executing == 0


def wait_until(condition, timeout_s: float, poll_s: float = 0.5) -> bool:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(poll_s)
    return condition()


@pytest.mark.parametrize("effects", [{"backlash": None}, {}], ids=["backlash", "clean"])
def test_the_cluster_gives_the_local_diagnosis(cluster, tmp_path, effects):
    address, client = cluster
    train, holdout = record_case(tmp_path, effects, seed=3)
    local = diagnose_logs([train], [holdout], settings=SETTINGS)
    with dask_executor(address) as executor:
        remote = diagnose_logs([train], [holdout], settings=SETTINGS, executor=executor)
    assert remote["verdict"]["effect"] == local["verdict"]["effect"] == ("backlash" if effects else "none")
    assert without_clock(remote) == without_clock(local)
    assert wait_until(lambda: cluster_idle(client), 60.0), "the diagnosis left tasks on the cluster"


def test_crest_gap_runs_its_fits_on_the_scheduler(cluster, tmp_path):
    address, client = cluster
    train, holdout = record_case(tmp_path, {"backlash": None}, seed=3)
    run = crest("gap", str(train), "--holdout", str(holdout), "--scheduler", address, "--effects",
                ",".join(SETTINGS.effects), "--json", str(tmp_path / "gap.json"), "--report", str(tmp_path / "report"),
                timeout_s=1800.0)
    assert run.returncode == 0, run.stderr
    assert f"fits run on the Dask cluster at {address}" in run.stderr
    assert "verdict: backlash" in run.stdout
    # only the effects asked for were fitted, and the output and the report say the verdict is among them
    said = "candidates: only backlash, tracker_offset, gravity (3 of the catalog's 11 effects, --effects)"
    assert said in run.stdout and said in (tmp_path / "report" / "report.md").read_text()
    result = json.loads((tmp_path / "gap.json").read_text())
    assert result["verdict"]["effect"] == "backlash"
    # a gear play alone is most of the gap: the grade says so on stdout and in the report
    assert result["verdict"]["confidence"] == "confident"
    assert result["verdict"]["confidence_line"] in run.stdout.splitlines()
    assert f"- {result['verdict']['confidence_line']}" in (tmp_path / "report" / "report.md").read_text()
    assert {c["effect"] for c in result["candidates"]} == set(SETTINGS.effects)
    # the logs come from a model plant written straight to files: no virtual testbed's plant in their sidecars
    assert result["log_plants"] == {str(train): None, str(holdout): None}
    assert "logs with no plant in their sidecar" in run.stdout
    # the scheduler ran the candidate fits (it keeps per-task-name statistics after the tasks are gone)
    prefixes = client.run_on_scheduler(lambda dask_scheduler: sorted(dask_scheduler.task_prefixes))
    assert "run_task" in prefixes and "calibrate" in prefixes, prefixes


def test_an_address_without_a_scheduler_is_refused_before_any_work(tmp_path):
    with socket.socket() as probe:          # a port that nothing listens on
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    train, holdout = tmp_path / "train.csv", tmp_path / "holdout.csv"
    for bad, says in ((f"tcp://127.0.0.1:{port}", "no Dask scheduler answers there"),
                      ("127.0.0.1:8786", "give a Dask scheduler address as tcp://HOST:PORT")):
        run = crest("gap", str(train), "--holdout", str(holdout), "--scheduler", bad, timeout_s=240.0)
        assert run.returncode == ExitCode.ERROR
        lines = run.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("crest: error: --scheduler") and says in lines[0], run.stderr


def test_ctrl_c_during_a_cluster_blind_benchmark_cancels_its_tasks(cluster, tmp_path):
    address, client = cluster
    assert wait_until(lambda: cluster_idle(client), 300.0)
    run = start_crest("gap", "--blind-benchmark", "--cases", "1", "--short", "--seed", "5", "--scheduler", address,
                      "--work-dir", str(tmp_path / "blind"), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                      text=True)
    try:
        # the case is recorded here first; then its baseline's fits appear on the cluster
        busy = wait_until(lambda: run.poll() is not None or sum(len(k) for k in client.processing().values()) > 0,
                          1200.0, poll_s=1.0)
        assert busy and run.poll() is None, "no fit reached the cluster"
        run.send_signal(signal.SIGINT)
        out, err = run.communicate(timeout=300.0)
    finally:
        if run.poll() is None:
            run.kill()
            run.communicate()
    assert run.returncode == ExitCode.INTERRUPTED, err
    assert err.strip().splitlines()[-1] == "crest: stopped by Ctrl-C"
    assert "Traceback" not in err and err.count("crest: ") == 1, err
    # a fit already running finishes on its worker (a thread is not killed); its result is dropped
    assert wait_until(lambda: cluster_idle(client), 600.0), "tasks left on the cluster after Ctrl-C"
