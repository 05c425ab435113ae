"""The one executor for printgen's parallel work.

Work that stays on this machine runs on the local pool (`printgen.executor.local`): worker
processes that die with their parent (SIGKILL included), leave signals to it and honour its
time limit; `run_jobs`, `shared_pool` and `helper` are make's and verify's, and `open_runner`
gives the sweeps of `printgen design` and `printgen series` the same workers. Only work that
may leave the machine goes to Dask: `open_runner(scheduler=...)`, a running
`dask.distributed` scheduler (`printgen.executor.dask`). How workers start (fork, fork server,
spawn) is `printgen.executor.start`'s; how signals end a run, `printgen.executor.signals`'s.

    with open_runner(workers=None) as run:          # this machine: all cores, processes
        out = run.map(screen_batch, batches, shared=ctx, label="screening")
    with open_runner(scheduler="tcp://host:8786") as run: ...   # a running Dask cluster
    with open_runner(serial=True) as run: ...       # in this process

Each task is `fn(shared, item)`, a pure function of its record, so the result is the same
wherever it runs, and the results come back in input order.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from printgen.executor.runner import Runner, batches, open_runner

__all__ = ["Runner", "batches", "open_runner"]


def __getattr__(name: str) -> Any:
    """`Runner`, `open_runner` and `batches` (`printgen.executor.runner`), imported when first
    asked for: the command line imports `printgen.executor.signals` first thing, before its
    heavy imports, and so this package, which must then import nothing."""
    if name in __all__:
        from printgen.executor import runner

        return getattr(runner, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
