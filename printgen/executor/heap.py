"""glibc's heap in a Dask worker: a task's large arrays reused from the heap, not mapped afresh.

distributed's nanny starts its workers with MALLOC_TRIM_THRESHOLD_ set (65536 by default, its
`distributed.nanny.pre-spawn-environ`), so that freed memory goes back to the system. Any
threshold set turns glibc's dynamic mmap threshold off: every array over M_MMAP_THRESHOLD's
128 KiB default (a GMRES basis of a solve of 2k unknowns, a net's strand arrays) is then mapped
at each allocation, faulted in page by page and unmapped when freed. On the design search's
verification (a batch of four 1:40 candidate sweeps, one worker) that cost ~50k minor page
faults and 0.09-0.17 s of system CPU a batch, against ~2k faults and 0.01 s in a worker of the
local pool; with the thresholds of `roomy`, the same as there.

`roomy` raises both thresholds while a task runs and sets back the ones the environment gave
after it (tasks that overlap in a worker's threads share one raise). Where the environment sets
neither (the dynamic threshold is on, as in the local pool), or off glibc, it does nothing.
"""

from __future__ import annotations

import ctypes
import os
import platform
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

M_TRIM_THRESHOLD = -1  # glibc's mallopt parameters (malloc.h)
M_MMAP_THRESHOLD = -3
MMAP_THRESHOLD = 32 * 1024 * 1024  # the dynamic threshold's own ceiling on 64-bit glibc
TRIM_THRESHOLD = 2 * MMAP_THRESHOLD  # twice the mmap threshold, as glibc's dynamic rule keeps it
DEFAULTS = {"MALLOC_TRIM_THRESHOLD_": 128 * 1024, "MALLOC_MMAP_THRESHOLD_": 128 * 1024}  # glibc's

_LOCK = threading.Lock()
_depth = [0]  # tasks inside `roomy` in this process


def _libc() -> Any:
    """glibc's mallopt holder, or None off glibc."""
    if platform.system() != "Linux" or platform.libc_ver()[0] != "glibc":
        return None
    lib = ctypes.CDLL(None)
    return lib if hasattr(lib, "mallopt") else None


def _set_by_environment() -> dict[str, int] | None:
    """The thresholds the environment set (glibc's default for the other one), or None when
    it sets neither or a value glibc would not take either."""
    named = {k: os.environ[k] for k in DEFAULTS if k in os.environ}
    if not named:
        return None
    try:
        return {k: int(named.get(k, v)) for k, v in DEFAULTS.items()}
    except ValueError:
        return None


@contextmanager
def roomy() -> Iterator[None]:
    """Heap thresholds raised (MMAP_THRESHOLD, TRIM_THRESHOLD) for the block when the
    environment fixed them; the environment's set back when the last such block ends."""
    given = _set_by_environment()
    lib = None if given is None else _libc()
    if lib is None or given is None:
        yield
        return
    with _LOCK:
        if not _depth[0]:
            lib.mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD)
            lib.mallopt(M_TRIM_THRESHOLD, TRIM_THRESHOLD)
        _depth[0] += 1
    try:
        yield
    finally:
        with _LOCK:
            _depth[0] -= 1
            if not _depth[0]:
                lib.mallopt(M_MMAP_THRESHOLD, given["MALLOC_MMAP_THRESHOLD_"])
                lib.mallopt(M_TRIM_THRESHOLD, given["MALLOC_TRIM_THRESHOLD_"])
