"""A timeline of a run, for benchmarks/bench_timeline.py: with PRINTGEN_TRACE set to a file,
every process of the run (make, its helper, their workers) appends one JSON line per span:
make's steps, the helper's phases, each pool's life and each job it ran
(printgen.executor.local wraps the jobs). Without it, nothing is written and nothing wrapped."""

from __future__ import annotations

import contextlib
import json
import os
import time
from collections.abc import Callable, Iterator
from typing import Any

TRACE = "PRINTGEN_TRACE"  # env var: a file every process appends its spans to (`span`)


@contextlib.contextmanager
def span(what: str) -> Iterator[None]:
    """With PRINTGEN_TRACE set to a file, append one JSON line for the block to it: process
    id, parent's, `what`, start and end (time.time(), comparable across processes), its CPU
    (benchmarks/bench_timeline.py draws them). Without it, nothing."""
    path = os.environ.get(TRACE)
    if not path:
        yield
        return
    t, cpu = time.time(), time.process_time()
    try:
        yield
    finally:
        line = json.dumps({"pid": os.getpid(), "ppid": os.getppid(), "what": what, "start": t,
                           "end": time.time(), "cpu": time.process_time() - cpu})
        with contextlib.suppress(OSError), open(path, "a") as f:  # one short append per line
            f.write(line + "\n")


def _traced(what: str, fn: Callable, /, *args: Any, **kwargs: Any) -> Any:
    with span(what):
        return fn(*args, **kwargs)


def traced_job(fn: Callable, args: tuple, kwargs: dict) -> tuple:
    """The job (fn, args, kwargs), in a `span` named by fn and its first argument with a
    `label` or `name` (a variant, a scene) when tracing."""
    if not os.environ.get(TRACE):
        return fn, args, kwargs
    named = [str(getattr(a, k)) for k in ("label", "name") for a in args
             if isinstance(getattr(a, k, None), str)]
    what = getattr(fn, "__name__", "job") + (f" {named[0]}" if named else "")
    return _traced, (what, fn, *args), kwargs
