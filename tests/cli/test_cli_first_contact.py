"""A new user's first minutes: crest installed from a wheel works, and the first run says why it waits."""
import os
import shutil
import subprocess
import sys
from pathlib import Path

from cli_runner import REPO, crest, start_crest
from crest.cli.compile_notice import COMPILE_NOTICE

SOURCES = ("crest", "model", "control", "sim_backend", "configs")


def test_a_non_editable_install_finds_its_configs_and_eds(tmp_path):
    """Slow (about a minute): builds a wheel of the repo, installs it into a fresh venv, runs
    `crest status` from a folder outside the repo, with the default config and with a copy of it."""
    source = tmp_path / "source"                    # a copy, so the build leaves nothing in the repo
    for name in SOURCES:
        shutil.copytree(REPO / name, source / name, ignore=shutil.ignore_patterns("__pycache__"))
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(REPO / name, source / name)
    pip = [sys.executable, "-m", "pip"]
    subprocess.run([*pip, "wheel", "--no-deps", "--no-build-isolation", "-q", "-w", str(tmp_path / "dist"),
                    str(source)], check=True, capture_output=True, timeout=600)
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True, timeout=120)
    python = venv / "bin" / "python"
    site_packages = Path(subprocess.run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                                        check=True, capture_output=True, text=True).stdout.strip())
    wheel, = (tmp_path / "dist").glob("crest_hil-*.whl")
    subprocess.run([*pip, "--python", str(python), "install", "--no-deps", "-q", str(wheel)], check=True,
                   capture_output=True, timeout=600)
    # then the dependencies (numpy, numba, canopen, ...) from this interpreter's site-packages, never the repo.
    # After the install: were they visible before it, pip would find an installed crest-hil there (as in CI,
    # which installs the repo) and install nothing.
    dependencies = [path for path in sys.path if path.endswith("site-packages")]
    (site_packages / "test_dependencies.pth").write_text("\n".join(dependencies) + "\n")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
    env["NUMBA_DISABLE_JIT"] = "1"                   # packaging is under test here, not the compiler

    where = subprocess.run([str(python), "-c", "import configs, crest, model; print(crest.__file__, model.__file__, "
                                               "configs.CONFIG_DIR)"],
                           cwd=elsewhere, env=env, check=True, capture_output=True, text=True).stdout.split()
    assert all(Path(path).is_relative_to(site_packages) for path in where), where

    status = subprocess.run([str(venv / "bin" / "crest"), "status"], cwd=elsewhere, env=env, capture_output=True,
                            text=True, timeout=600)
    assert status.returncode == 0, status.stderr
    assert "tendon1" in status.stdout and "insertion" in status.stdout

    shutil.copy(site_packages / "configs" / "testbed.toml", elsewhere / "testbed.toml")   # the README's recipe
    copied = subprocess.run([str(venv / "bin" / "crest"), "status", "--config", "testbed.toml"], cwd=elsewhere,
                            env=env, capture_output=True, text=True, timeout=600)
    assert copied.returncode == 0, copied.stderr
    assert "tendon1" in copied.stdout


def test_the_first_run_says_the_kernel_is_compiling(tmp_path):
    """An empty numba cache: the notice comes before the long compile (the run is stopped then)."""
    process = start_crest("status", stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True,
                          env={"NUMBA_CACHE_DIR": str(tmp_path / "numba_cache")})
    lines = []
    try:
        while COMPILE_NOTICE not in lines and (line := process.stderr.readline()):
            lines.append(line.rstrip("\n"))
    finally:
        process.kill()
        process.wait(timeout=60)
    assert COMPILE_NOTICE in lines


def test_a_cached_kernel_starts_without_the_notice():
    crest("status")                                  # compiles into the repo's cache if it is still empty
    result = crest("status")
    assert result.returncode == 0, result.stderr
    assert COMPILE_NOTICE not in result.stderr


def test_estop_starts_without_loading_the_model():
    """`crest estop` must act at once: it never runs the model, so it never pays for importing numba and
    the model's kernels (more than half a second) before it reaches the drives."""
    result = subprocess.run([sys.executable, "-X", "importtime", "-m", "crest.cli.main", "estop"], cwd=REPO,
                            capture_output=True, text=True, timeout=240)
    imported = {line.split("|")[-1].strip() for line in result.stderr.splitlines() if line.startswith("import time:")}
    assert "crest.driver" in imported and "crest.backend" in imported     # what it does need
    assert not {"numba", "model", "control", "scipy"} & imported, sorted({"numba", "model", "control", "scipy"} & imported)
    assert "nothing was stopped: no virtual testbed is running" in result.stderr     # and it still says what it did
