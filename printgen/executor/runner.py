"""`open_runner` and its `Runner`: a sweep's tasks mapped over the local pool, a Dask
scheduler, or this process (see the package's docstring, `printgen.executor`).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import as_completed
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

from printgen.errors import InputError
from printgen.executor.local import Pool, collect, shared_pool
from printgen.executor.start import cores

log = logging.getLogger(__name__)


@dataclass
class Runner:
    """Maps tasks over records: on the local pool (`pool`), on a Dask client (`client`), or
    in this process when both are None."""

    where: str
    pool: Pool | None = None
    client: Any = None
    progress: bool = False

    @property
    def workers(self) -> int:
        """Workers available (1 when serial)."""
        if self.client is not None:
            info = self.client.scheduler_info()["workers"]
            return max(1, sum(w.get("nthreads", 1) for w in info.values()))
        return 1 if self.pool is None else self.pool.size

    def map(self, fn: Callable[[Any, Any], Any], items: Sequence[Any], *, shared: Any = None,
            label: str = "sweep") -> list[Any]:
        """[fn(shared, item) for item in items], in order; a failing task raises its error."""
        with _bar(self.progress, label, len(items)) as advance:
            if self.client is not None:
                from printgen.executor.dask import map_on

                return map_on(self.client, fn, items, shared, advance)
            if self.pool is not None:
                futures = [self.pool.submit(fn, shared, item) for item in items]
                for _ in as_completed(futures):
                    advance()
                return collect(futures)
            out = []
            for item in items:
                out.append(fn(shared, item))
                advance()
            return out

    def map_then(self, fn: Callable[[Any, Any], Any], items: Sequence[Any],
                 then: Callable[[Any], tuple[Callable[[Any, Any], Any], Sequence[Any], Any]], *,
                 shared: Any = None, label: str = "sweep") -> tuple[list[Any], list[Any]]:
        """(`map(fn, items)`, the results of the tasks `then(result of items[0])` gives as
        (fn2, items2, shared2)): on the local pool those start as soon as the first item's
        result is in, queued behind the rest of `items`, so that work waiting on one result
        fills the cores the others leave; serially or on Dask, after the whole first map."""
        if self.pool is None or self.client is not None:
            first = self.map(fn, items, shared=shared, label=label)
            fn2, items2, shared2 = then(first[0])
            return first, self.map(fn2, items2, shared=shared2, label=label)
        futures = [self.pool.submit(fn, shared, item) for item in items]
        fn2, items2, shared2 = then(collect(futures[:1])[0])
        more = [self.pool.submit(fn2, shared2, item) for item in items2]
        with _bar(self.progress, label, len(futures) + len(more)) as advance:
            for _ in as_completed(futures + more):
                advance()
        return collect(futures), collect(more)


@contextmanager
def _bar(show: bool, label: str, total: int) -> Iterator[Callable[[], None]]:
    """A rich progress bar on stderr when it is a terminal (or nothing: in a log the bar's
    redraws are noise, and a run that fails or is stopped must end in one line): yields the
    function that advances it. Erased when the block ends in an error or a signal."""
    from rich.console import Console

    console = Console(stderr=True)
    if not show or not console.is_terminal:
        yield lambda: None
        return
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeElapsedColumn

    with Progress("[progress.description]{task.description}", BarColumn(),
                  MofNCompleteColumn(), TimeElapsedColumn(),
                  console=console, transient=False) as bar:
        task = bar.add_task(label, total=total)
        try:
            yield lambda: bar.advance(task)
        except BaseException:
            bar.live.transient = True  # the error's (or the signal's) line stands alone
            raise


@contextmanager
def open_runner(*, scheduler: str | None = None, workers: int | None = None,
                serial: bool = False, progress: bool = False) -> Iterator[Runner]:
    """A Runner: serial; a client of the Dask scheduler at `scheduler` (work that may leave
    the machine); else the local pool of `workers` processes (default: every core), whose
    workers die with this process. Closed on exit, error or Ctrl-C (the local workers killed
    on an error or a signal)."""
    if serial:
        yield Runner("serial (this process)", progress=progress)
        return
    if workers is not None and not 1 <= workers <= cores():
        raise InputError(f"--workers {workers} must be from 1 to {cores()}, the cores this "
                         "machine gives printgen (more workers than cores only compete for "
                         "them); leave it out to use every core")
    if scheduler:
        from printgen.executor.dask import client

        with client(scheduler) as c:
            log.info("sweep on Dask scheduler %s", scheduler)
            yield Runner(f"Dask scheduler {scheduler}", client=c, progress=progress)
        return
    n = workers or cores()
    with shared_pool(n) as pool:
        where = f"local pool ({n} worker processes)" if pool.workers else "serial (this process)"
        log.info("sweep on %s", where)
        yield Runner(where, pool=pool, progress=progress)


def batches(items: Sequence[Any], workers: int, *, per_worker: int = 4,
            max_size: int = 2048) -> list[list[Any]]:
    """Split cheap tasks into about `per_worker` batches per worker (at most `max_size` items
    each), so that scheduling overhead does not swamp the work. Order is kept."""
    n = max(1, min(max_size, -(-len(items) // max(1, workers * per_worker))))
    return [list(items[i:i + n]) for i in range(0, len(items), n)]
