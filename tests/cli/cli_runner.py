"""Run the `crest` CLI as a user would: a separate process, its output and exit code."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

CREST = [sys.executable, "-m", "crest.cli.main"]
REPO = Path(__file__).resolve().parents[2]


def crest(*args: str, timeout_s: float = 240.0, cwd: Path | None = None,
          env: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    """Run crest to the end; env adds to (or overrides) this process's environment."""
    env = dict(os.environ, PYTHONUNBUFFERED="1", **(env or {}))
    return subprocess.run([*CREST, *args], capture_output=True, text=True, timeout=timeout_s,
                          cwd=cwd or REPO, env=env)


def start_crest(*args: str, cwd: Path | None = None, env: dict[str, str] | None = None,
                **kwargs) -> subprocess.Popen:
    env = dict(os.environ, PYTHONUNBUFFERED="1", **(env or {}))
    return subprocess.Popen([*CREST, *args], cwd=cwd or REPO, env=env, **kwargs)
