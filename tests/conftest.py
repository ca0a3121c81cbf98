"""Every test gets a runtime folder of its own for the served virtual testbed's state file.

A real-time crest command that finds no served testbed starts one (crest.testbed_service); the
state file in $XDG_RUNTIME_DIR/crest is how other processes find it. A folder per test keeps a
test from joining a testbed another test (or the user's own `crest testbed serve`) left running.
"""
from __future__ import annotations

import pytest


@pytest.fixture(autouse=True)
def own_runtime_dir(tmp_path_factory, monkeypatch):
    folder = tmp_path_factory.mktemp("runtime")
    folder.chmod(0o700)
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(folder))
    return folder
