"""Session set-up shared by every test.

The numba kernels (the model's and the rod plant's, the two at once in two processes) are compiled
once, before pytest-xdist starts its workers (`pytest_configure`). The controller also makes the run's shared folder
($CREST_TEST_SHARED_DIR, removed at the end), where a result that several workers need is computed
once (tests.gap.conftest.diagnosed).

Every test gets a runtime folder of its own for the served virtual testbed's state file. A
real-time crest command that finds no served testbed starts one (crest.testbed_service); the
state file in $XDG_RUNTIME_DIR/crest is how other processes find it. A folder per test keeps a
test from joining a testbed another test (or the user's own `crest testbed serve`) left running.
"""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile

import pytest

SHARED_DIR_VARIABLE = "CREST_TEST_SHARED_DIR"
ROD_KERNEL_WARM_UP = "from sim_backend.plant.rod.rod_plant import RodPlant; RodPlant().step(0.01, [0.5, 0, 0, 0], 0.0)"


def pytest_configure(config):
    """Compile the numba kernels here, in the one process that starts the xdist workers.

    numba caches them on disk (model/jit.py), so the workers and every crest process a test starts
    load them. On an empty cache (a clean checkout in CI) each of those processes would otherwise
    compile its own copy at once, half a minute of a core each on an idle machine. Without xdist
    (`pytest` alone, or `-n 0`) nothing is compiled ahead: a test that needs no model does not wait.
    """
    if hasattr(config, "workerinput") or not config.getoption("numprocesses", default=None):
        return      # an xdist worker (the controller has compiled them), or one process: it compiles as it goes
    os.environ[SHARED_DIR_VARIABLE] = tempfile.mkdtemp(prefix="crest-tests-")     # the workers inherit it
    # the rod plant's kernel compiles in a second process meanwhile: numba compiles on one core
    rod = subprocess.Popen([sys.executable, "-c", ROD_KERNEL_WARM_UP], cwd=config.rootpath)
    try:
        from model import CatheterParams, ConstantCurvature, DahlCatheter
        params, pull_mm = CatheterParams.from_toml(), [0.5, 0.0, 0.0, 0.0]
        catheter = DahlCatheter(params, n_elements=4)
        catheter.move_to(pull_mm)
        _ = catheter.backbone_mm
        ConstantCurvature(params).tip_mm(pull_mm, 50.0)
        ConstantCurvature(params).backbone_mm(pull_mm, 50.0)
    except BaseException:
        rod.kill()          # the session ends here: the process it started ends with it
        rod.wait()
        raise
    if rod.wait() != 0:
        raise pytest.UsageError(f"compiling the rod plant's kernel failed (exit {rod.returncode}); see its traceback above")


def pytest_unconfigure(config):
    if not hasattr(config, "workerinput") and SHARED_DIR_VARIABLE in os.environ:
        shutil.rmtree(os.environ.pop(SHARED_DIR_VARIABLE), ignore_errors=True)


@pytest.fixture(autouse=True)
def own_runtime_dir(tmp_path_factory, monkeypatch):
    folder = tmp_path_factory.mktemp("runtime")
    folder.chmod(0o700)
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(folder))
    return folder
