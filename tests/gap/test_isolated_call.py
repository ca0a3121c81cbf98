"""Isolated calls (blind benchmark): a result comes back, an exception comes back, and a call that does not
return in time, or is interrupted by Ctrl-C, is ended with its whole process group."""
import os
import signal
import threading
import time

import pytest

from crest.gap.isolated_call import CallCancelled, CallTimedOut, call_isolated


def child_pid_then_sleep(path, seconds):
    with open(path, "w") as handle:
        handle.write(str(os.getpid()))
    time.sleep(seconds)


def fail(message):
    raise ValueError(message)


def assert_ended(pid_path):
    """The process whose pid the child wrote no longer exists."""
    pid = int(pid_path.read_text())
    with pytest.raises(ProcessLookupError):
        os.kill(pid, 0)


def test_result_and_exception_come_back():
    assert call_isolated(pow, 2, 10, timeout_s=30.0) == 1024
    with pytest.raises(ValueError, match="bad input"):
        call_isolated(fail, "bad input", timeout_s=30.0)


def test_a_call_that_does_not_return_is_killed(tmp_path):
    start = time.monotonic()
    with pytest.raises(CallTimedOut):
        call_isolated(child_pid_then_sleep, tmp_path / "pid", 60.0, timeout_s=1.0)
    assert time.monotonic() - start < 10.0
    assert_ended(tmp_path / "pid")


def test_ctrl_c_while_waiting_kills_the_call(tmp_path):
    def ctrl_c(signum, frame):
        raise KeyboardInterrupt
    previous = signal.signal(signal.SIGALRM, ctrl_c)
    signal.setitimer(signal.ITIMER_REAL, 2.0)
    start = time.monotonic()
    try:
        with pytest.raises(KeyboardInterrupt):
            call_isolated(child_pid_then_sleep, tmp_path / "pid", 60.0, timeout_s=60.0)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, previous)
    assert time.monotonic() - start < 10.0
    assert_ended(tmp_path / "pid")


def test_a_call_waited_for_in_a_thread_is_killed_when_cancelled(tmp_path):
    """Ctrl-C reaches only the main thread: it ends a call another thread waits for through its event."""
    cancel = threading.Event()
    outcome = []

    def wait_in_thread():
        try:
            call_isolated(child_pid_then_sleep, tmp_path / "pid", 60.0, timeout_s=60.0, cancel=cancel)
        except CallCancelled as error:
            outcome.append(error)

    waiter = threading.Thread(target=wait_in_thread)
    waiter.start()
    deadline = time.monotonic() + 60.0
    while not (tmp_path / "pid").exists() or not (tmp_path / "pid").read_text():
        assert time.monotonic() < deadline, "the child never started"
        time.sleep(0.05)
    cancel.set()
    waiter.join(timeout=30.0)
    assert not waiter.is_alive() and len(outcome) == 1
    assert_ended(tmp_path / "pid")
