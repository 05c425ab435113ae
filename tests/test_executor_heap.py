"""The heap thresholds of a task on a Dask worker (`printgen.executor.heap.roomy`)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from printgen.executor import heap

FEWER = 10  # the raised thresholds fault at least 10x fewer pages (measured: ~3000x)


class _Recorder:
    """Stands in for glibc: records mallopt calls."""

    def __init__(self) -> None:
        self.calls: list[tuple[int, int]] = []

    def mallopt(self, param: int, value: int) -> int:
        self.calls.append((param, value))
        return 1


def test_roomy_raises_the_thresholds_and_sets_back_the_environments(monkeypatch):
    lib = _Recorder()
    monkeypatch.setattr(heap, "_libc", lambda: lib)
    monkeypatch.setenv("MALLOC_TRIM_THRESHOLD_", "65536")
    monkeypatch.delenv("MALLOC_MMAP_THRESHOLD_", raising=False)
    with heap.roomy(), heap.roomy():  # overlapping tasks: one raise, one set-back
        assert lib.calls == [(heap.M_MMAP_THRESHOLD, heap.MMAP_THRESHOLD),
                             (heap.M_TRIM_THRESHOLD, heap.TRIM_THRESHOLD)]
    assert lib.calls[2:] == [(heap.M_MMAP_THRESHOLD, 128 * 1024),
                             (heap.M_TRIM_THRESHOLD, 65536)]


@pytest.mark.parametrize("env", [{}, {"MALLOC_TRIM_THRESHOLD_": "lots"}])
def test_roomy_leaves_a_heap_the_environment_did_not_fix_alone(monkeypatch, env):
    """No threshold set (glibc's dynamic threshold on, as in the local pool), or one glibc
    would not read: no call."""
    lib = _Recorder()
    monkeypatch.setattr(heap, "_libc", lambda: lib)
    for k in heap.DEFAULTS:
        monkeypatch.delenv(k, raising=False)
    for k, v in env.items():
        monkeypatch.setenv(k, v)
    with heap.roomy():
        pass
    assert lib.calls == []


PROBE = """
import resource, numpy as np
from printgen.executor.heap import roomy

def faults():
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    for _ in range(200):
        a = np.ones(1 << 17)  # 1 MiB, over the 128 KiB mmap threshold
        del a
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before

faults()  # numpy's own first allocations
outside = faults()
with roomy():
    faults()  # the first one after the raise grows the heap
    inside = faults()
print(outside, inside)
"""


@pytest.mark.skipif(heap._libc() is None, reason="glibc only")
def test_roomy_stops_the_page_faults_of_a_worker_whose_threshold_is_fixed():
    """In a process started as distributed starts its workers (MALLOC_TRIM_THRESHOLD_=65536),
    a 1 MiB array allocated again and again faults its pages in every time; inside `roomy`
    it is reused from the heap."""
    import os

    env = {**os.environ, "MALLOC_TRIM_THRESHOLD_": "65536"}
    out = subprocess.run([sys.executable, "-c", PROBE], env=env, capture_output=True,
                         text=True, check=True)
    outside, inside = (int(x) for x in out.stdout.split())
    assert outside > 200 * 100  # 256 pages per array: the case is exercised
    assert inside * FEWER < outside
