"""Isolated calls (blind benchmark): a result comes back, an exception comes back, and a call that does not
return in time is ended with its whole process group."""
import os
import time

import pytest

from crest.gap.isolated_call import CallTimedOut, call_isolated


def child_pid_then_sleep(path, seconds):
    with open(path, "w") as handle:
        handle.write(str(os.getpid()))
    time.sleep(seconds)


def fail(message):
    raise ValueError(message)


def test_result_and_exception_come_back():
    assert call_isolated(pow, 2, 10, timeout_s=30.0) == 1024
    with pytest.raises(ValueError, match="bad input"):
        call_isolated(fail, "bad input", timeout_s=30.0)


def test_a_call_that_does_not_return_is_killed(tmp_path):
    start = time.monotonic()
    with pytest.raises(CallTimedOut):
        call_isolated(child_pid_then_sleep, tmp_path / "pid", 60.0, timeout_s=1.0)
    assert time.monotonic() - start < 10.0
    pid = int((tmp_path / "pid").read_text())
    with pytest.raises(ProcessLookupError):
        os.kill(pid, 0)
