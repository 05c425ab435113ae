"""Timing helper shared by the benchmarks."""

from __future__ import annotations

import time


def best_of(fn, repeat: int):
    """(best wall time in s over `repeat` calls, the last result)."""
    best, out = float("inf"), None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out
