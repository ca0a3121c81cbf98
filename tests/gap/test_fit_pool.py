"""The fits' process pool runs every BLAS with one thread, in its workers and where fits run here."""
from threadpoolctl import threadpool_info

from crest.gap.fit_executor import local_executor
from model.gap.fit_pool import fit_pool


def blas_threads() -> list[int]:
    """Threads of each BLAS library loaded in this process (numpy's OpenBLAS at least)."""
    import numpy  # noqa: F401  (loads the BLAS)

    return [library["num_threads"] for library in threadpool_info() if library["user_api"] == "blas"]


def test_every_worker_of_the_fit_pool_uses_one_blas_thread():
    with fit_pool(2) as pool:
        per_worker = list(pool.map(_worker_blas_threads, range(4)))
    assert all(threads and set(threads) == {1} for threads in per_worker), per_worker


def test_fits_in_this_process_use_one_blas_thread_and_the_limit_ends_with_them():
    before = blas_threads()
    with local_executor(1) as pool:
        assert pool is None and set(blas_threads()) == {1}
    assert blas_threads() == before


def _worker_blas_threads(_: int) -> list[int]:
    return blas_threads()
