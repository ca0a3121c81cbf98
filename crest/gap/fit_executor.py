"""Where the gap diagnosis' fits run: local processes, or the workers of a Dask distributed cluster.

The fits (the baseline's starts, the candidate effects, the pairs, the blind benchmark's oracles)
are independent, picklable calls. The diagnosis hands them to a `concurrent.futures.Executor` and
collects the results in the order it submitted them, and the fits draw no random numbers, so the
result does not depend on which worker ran which fit or when it finished: a fixed seed gives the
same diagnosis locally and on a cluster.

`open_executor(None, workers)`: a local process pool (none for one worker; one BLAS thread per
process, `model.gap.fit_pool`), see `local_executor`.
`open_executor("tcp://HOST:PORT")`: the executor of a `distributed.Client` connected to a running
Dask scheduler (`Client.get_executor`; the scheduler and its workers are started with `dask
scheduler` and `dask worker`, and the workers must be able to import this project). The address is
checked and the scheduler reached, with a worker, before any work starts (an address where nothing
listens is refused at once; dask's client would retry it for its whole timeout). On leaving the context,
however it is left (Ctrl-C, SIGTERM, an error), every task still pending or running is cancelled
and the client is closed, so nothing is left on the cluster. Dask is imported here only: `model`
sees an Executor.
"""
from __future__ import annotations

import multiprocessing
import re
import socket
from collections.abc import Iterator
from concurrent.futures import Executor
from contextlib import contextmanager

from model.gap.fit_pool import fit_pool, one_blas_thread

CONNECT_TIMEOUT_S = 10.0
ADDRESS = re.compile(r"tcp://(?P<host>[A-Za-z0-9.\-]+):(?P<port>[0-9]{1,5})")


class SchedulerError(ValueError):
    """The --scheduler address is malformed, or no scheduler with a worker answers there."""


def check_scheduler_address(address: str) -> str:
    """The address if it has the form tcp://HOST:PORT (port 1-65535), else SchedulerError."""
    match = ADDRESS.fullmatch(address)
    if not match or not 1 <= int(match["port"]) <= 65535:
        raise SchedulerError(f"--scheduler {address!r}: give a Dask scheduler address as tcp://HOST:PORT, "
                             "e.g. tcp://127.0.0.1:8786 (the address `dask scheduler` prints)")
    return address


@contextmanager
def open_executor(scheduler: str | None = None, workers: int = 2) -> Iterator[Executor | None]:
    """The executor for the fits (see module doc): `workers` local processes, or the Dask cluster
    whose scheduler listens at `scheduler`."""
    if scheduler is None:
        with local_executor(workers) as pool:
            yield pool
        return
    with dask_executor(scheduler) as executor:
        yield executor


@contextmanager
def local_executor(workers: int) -> Iterator[Executor | None]:
    """`workers` local processes (None for one: the fits then run here, with one BLAS thread, see
    `model.gap.fit_pool`). Left by an exception (Ctrl-C, SIGTERM, an error), the
    fits not started are cancelled and the running ones' processes terminated at once: a pool's own
    exit would wait for them, minutes on a long log."""
    if workers <= 1:
        with one_blas_thread():
            yield None
        return
    pool = fit_pool(workers)
    try:
        yield pool
    except BaseException:
        pool.shutdown(wait=False, cancel_futures=True)
        for process in multiprocessing.active_children():
            process.terminate()
        raise
    pool.shutdown()


@contextmanager
def dask_executor(address: str) -> Iterator[Executor]:
    """The executor of a Dask client connected to the scheduler at `address` (tcp://HOST:PORT); its
    tasks are cancelled and the client closed on leaving, normally or not."""
    match = ADDRESS.fullmatch(check_scheduler_address(address))
    try:
        socket.create_connection((match["host"], int(match["port"])), timeout=CONNECT_TIMEOUT_S).close()
    except OSError as error:
        raise _no_scheduler(address, error) from None
    from distributed import Client     # only the cluster path needs dask

    try:
        client = Client(address, timeout=CONNECT_TIMEOUT_S, set_as_default=False)
    except (OSError, TimeoutError) as error:
        raise _no_scheduler(address, error) from None
    executor = None
    try:
        try:
            client.wait_for_workers(1, timeout=CONNECT_TIMEOUT_S)
        except TimeoutError:
            raise SchedulerError(f"--scheduler {address}: the scheduler has no worker (none joined within "
                                 f"{CONNECT_TIMEOUT_S:.0f} s); start one with `dask worker {address}` from this "
                                 "project's folder") from None
        executor = client.get_executor(pure=False)   # every call runs: no merging of equal-looking tasks
        yield executor
    finally:
        if executor is not None:
            executor.shutdown(wait=False)            # cancels the tasks still pending or running
        client.close()


def _no_scheduler(address: str, error: Exception) -> SchedulerError:
    return SchedulerError(f"--scheduler {address}: no Dask scheduler answers there within {CONNECT_TIMEOUT_S:.0f} s "
                          f"({error}); start one with `dask scheduler --host 127.0.0.1 --port PORT` and a worker with "
                          f"`dask worker {address}`, or leave out --scheduler to run on local processes")
