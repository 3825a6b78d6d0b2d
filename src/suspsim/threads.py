"""Worker threads of the compiled passes: numba's pool for the pair loops, one thread for BLAS.

numpy's OpenBLAS starts its own pool, one worker per CPU, at the first large ``np.dot`` (the
stress sample's kinetic term is one), and its workers spin after each call. On a 2-CPU machine
they then take CPU time from numba's workers until long after the call. Measured on the
32,768-particle Papanastasiou bench box with 2 numba threads: 6.2 ms per step before the
first stress sample, 11–16 ms per step after it, 6.2 ms with BLAS capped at one thread. The
solvers' BLAS calls are O(N) reductions and small dense products that gain nothing from
threads, so every solver caps BLAS at one thread for the process when it sets its threads.
"""
from __future__ import annotations

from functools import cache

import numba
from threadpoolctl import threadpool_limits


@cache
def _cap_blas() -> None:
    threadpool_limits(1, user_api="blas")


def use_threads(threads: int) -> None:
    """Run numba's parallel loops on ``threads`` threads and BLAS on one (module docstring)."""
    _cap_blas()
    numba.set_num_threads(threads)
