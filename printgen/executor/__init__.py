"""Sweeps on Dask: map a pure task over small records, serially, on a local cluster or on a
running `dask.distributed` scheduler, with the results in input order.

    with open_runner(workers=None) as run:          # LocalCluster: all cores, processes
        out = run.map(screen_batch, batches, shared=ctx, label="screening")
    with open_runner(scheduler="tcp://host:8786") as run: ...   # a running cluster
    with open_runner(serial=True) as run: ...       # no Dask: in this process

Each task is `fn(shared, item)`, a pure function of its record, so the result is the same
wherever it runs. The local cluster's workers are this process's children: the context managers
close the client and the cluster on a normal exit, an error or Ctrl-C, and worker processes are
daemonic, so they never outlive this process. No home-made pool: everything parallel is Dask.
"""

from __future__ import annotations

import ipaddress
import logging
import re
from collections.abc import Callable, Iterator, Sequence
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass
from typing import Any

from printgen.errors import InputError
from printgen.workers import cores

log = logging.getLogger(__name__)

INSTALL_HINT = "pip install 'printgen[sweep]' (dask[distributed])"
ADDRESS = re.compile(r"tcp://(?P<host>\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9](?:[A-Za-z0-9.-]*[A-Za-z0-9])?)"
                     r":(?P<port>[0-9]{1,5})")
CONNECT_TIMEOUT_S = 20  # a scheduler that does not answer within this is reported, not awaited


def _distributed():
    try:
        import distributed
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise InputError(f"design sweeps need dask.distributed: {INSTALL_HINT}") from exc
    return distributed


@dataclass
class Runner:
    """Maps tasks over records: on a Dask client, or in this process when `client` is None."""

    client: Any
    where: str
    progress: bool = False

    @property
    def workers(self) -> int:
        """Worker threads available (1 when serial)."""
        if self.client is None:
            return 1
        info = self.client.scheduler_info()["workers"]
        return max(1, sum(w.get("nthreads", 1) for w in info.values()))

    def map(self, fn: Callable[[Any, Any], Any], items: Sequence[Any], *, shared: Any = None,
            label: str = "sweep") -> list[Any]:
        """[fn(shared, item) for item in items], in order; a failing task raises its error."""
        with _bar(self.progress, label, len(items)) as advance:
            if self.client is None:
                out = []
                for item in items:
                    out.append(fn(shared, item))
                    advance()
                return out
            return self._map_dask(fn, items, shared, advance)

    def _map_dask(self, fn, items, shared, advance) -> list[Any]:
        distributed = _distributed()
        shared_f = self.client.scatter(shared, broadcast=True, hash=False)
        futures = [self.client.submit(fn, shared_f, item, pure=False) for item in items]
        try:
            for _ in distributed.as_completed(futures, loop=self.client.loop):
                advance()
            return self.client.gather(futures)
        finally:
            self.client.cancel([*futures, shared_f])


@contextmanager
def _bar(show: bool, label: str, total: int) -> Iterator[Callable[[], None]]:
    """A rich progress bar on stderr (or nothing): yields the function that advances it."""
    if not show:
        yield lambda: None
        return
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeElapsedColumn

    with Progress("[progress.description]{task.description}", BarColumn(),
                  MofNCompleteColumn(), TimeElapsedColumn(),
                  console=Console(stderr=True), transient=False) as bar:
        task = bar.add_task(label, total=total)
        yield lambda: bar.advance(task)


@contextmanager
def open_runner(*, scheduler: str | None = None, workers: int | None = None,
                serial: bool = False, progress: bool = False) -> Iterator[Runner]:
    """A Runner: serial, a Client to `scheduler` (address), else a LocalCluster of `workers`
    processes (default: every core), one thread each. Closed on exit, error or Ctrl-C."""
    if serial:
        yield Runner(None, "serial (this process)", progress)
        return
    if workers is not None and not 1 <= workers <= cores():
        raise InputError(f"--workers {workers} must be from 1 to {cores()}, the cores this "
                         "machine gives printgen (more workers than cores only compete for "
                         "them); leave it out to use every core")
    if scheduler:
        check_address(scheduler)  # before the (slow) import of distributed
    distributed = _distributed()
    with ExitStack() as stack:
        quiet = logging.getLogger("distributed")
        stack.callback(quiet.setLevel, quiet.level)
        quiet.setLevel(logging.ERROR)  # the cluster's chatter is not the user's business
        if scheduler:
            try:
                client = stack.enter_context(distributed.Client(
                    scheduler, timeout=CONNECT_TIMEOUT_S, set_as_default=False))
            except (OSError, TimeoutError) as exc:
                raise InputError(f"cannot reach the Dask scheduler {scheduler!r} within "
                                 f"{CONNECT_TIMEOUT_S} s ({exc}); start one with "
                                 "`dask scheduler` or leave out --scheduler") from exc
            where = f"Dask scheduler {scheduler}"
        else:
            n = workers or cores()
            cluster = stack.enter_context(distributed.LocalCluster(
                n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                silence_logs=logging.CRITICAL))
            client = stack.enter_context(distributed.Client(cluster, set_as_default=False))
            where = f"local Dask cluster ({n} worker processes)"
        log.info("sweep on %s", where)
        yield Runner(client, where, progress)


def check_address(address: str) -> str:
    """`address` when it is tcp://HOST:PORT (a host name, an IPv4 address or [IPv6]), else
    InputError: other schemes (file://, inproc://, tls://, ucx://) are not connected to."""
    m = ADDRESS.fullmatch(address)
    ok = m is not None and 1 <= int(m["port"]) <= 65535
    if ok and m["host"].startswith("["):
        try:
            ipaddress.IPv6Address(m["host"][1:-1])
        except ValueError:
            ok = False
    if not ok:
        raise InputError(f"--scheduler {address[:100]!r} is not a Dask scheduler address: give "
                         "tcp://HOST:PORT, e.g. tcp://10.0.0.5:8786 (the address `dask "
                         "scheduler` prints), or leave out --scheduler for a local cluster")
    return address


def batches(items: Sequence[Any], workers: int, *, per_worker: int = 4,
            max_size: int = 2048) -> list[list[Any]]:
    """Split cheap tasks into about `per_worker` batches per worker (at most `max_size` items
    each), so that scheduling overhead does not swamp the work. Order is kept."""
    n = max(1, min(max_size, -(-len(items) // max(1, workers * per_worker))))
    return [list(items[i:i + n]) for i in range(0, len(items), n)]
