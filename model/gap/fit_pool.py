"""The local process pool the fits run on: one process per core, one BLAS thread per process.

The fits are independent and CPU-bound, so they run in parallel processes. Each fit also calls
LAPACK (least_squares takes an SVD of the Jacobian at every iteration), and OpenBLAS starts a
thread per core in every process: two fit processes on two cores ran four BLAS threads, which
spin while they wait for work and took the cores from the fits. Measured on the drawn-plant log
of `crest bench --only gap` (one `backlash` candidate's fit, 2 cores, idle): 8.4 s alone; 11.8 and
12.0 s with two at once; 8.4 s each with two at once and one BLAS thread per process. Alone, a
second BLAS thread gained nothing (8.3 s with one). threadpoolctl sets the limit in each worker
as it starts.

The thread count also changes LAPACK's rounding, and a fit's path through a ridged cost follows
it (the same baseline fit ended at EI 644 with two BLAS threads and 630 with one, at the same
training RMSE). Fits in the calling process (one worker) therefore run with one BLAS thread too
(`one_blas_thread`), as do a Dask cluster's workers (its nanny sets it), so a diagnosis does not
depend on where its fits ran or on the machine's core count.
"""
from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor

from threadpoolctl import threadpool_limits


def fit_pool(workers: int) -> ProcessPoolExecutor:
    """A pool of `workers` processes whose BLAS and OpenMP libraries each use one thread."""
    return ProcessPoolExecutor(workers, initializer=_one_thread_per_library)


def one_blas_thread():
    """A context in which this process's BLAS and OpenMP libraries use one thread (see module doc)."""
    return threadpool_limits(1)


def _one_thread_per_library() -> None:
    threadpool_limits(1)     # for the worker's whole life
