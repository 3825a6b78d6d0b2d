"""The solvers' thread settings: numba's pool as asked, BLAS on one thread (suspsim.threads)."""
import numba
from threadpoolctl import threadpool_info

from suspsim.threads import use_threads


def test_use_threads_sets_numba_and_caps_blas():
    use_threads(1)
    assert numba.get_num_threads() == 1
    blas = [pool for pool in threadpool_info() if pool["user_api"] == "blas"]
    assert blas, "numpy's BLAS is not visible to threadpoolctl"
    assert all(pool["num_threads"] == 1 for pool in blas)
    use_threads(numba.config.NUMBA_NUM_THREADS)
    assert numba.get_num_threads() == numba.config.NUMBA_NUM_THREADS
