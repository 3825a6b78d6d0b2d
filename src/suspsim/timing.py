"""Best-of-n wall times of callables, for the benchmarks' per-pass figures."""
from __future__ import annotations

import time
from typing import Callable, Mapping

__all__ = ["best_times"]


def best_times(calls: Mapping[str, Callable[[], object]], repeats: int) -> dict[str, float]:
    """Per name, the shortest of ``repeats`` wall times [s] of its call, after one untimed call
    (compilation, caches). Calls run in the mapping's order."""
    best = {}
    for name, call in calls.items():
        call()
        times = []
        for _ in range(repeats):
            start = time.perf_counter()
            call()
            times.append(time.perf_counter() - start)
        best[name] = min(times)
    return best
