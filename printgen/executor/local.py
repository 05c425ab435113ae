"""The local pool: worker processes on this machine that die with their parent.

`run_jobs` runs independent jobs in a process pool whose workers die with their parent, so a
`make` killed by SIGKILL leaves no orphan: on Linux the kernel kills them
(`prctl(PR_SET_PDEATHSIG, SIGKILL)` in the initializer) when the parent forked the worker
itself; elsewhere, and under `forkserver` (whose workers are the fork server's children), a
watchdog thread in each worker waits on multiprocessing's parent sentinel and exits when it
fires. How they start is `printgen.executor.start`'s (`start_method`). The workers ignore
SIGINT, SIGTERM and SIGHUP: the parent handles those (`printgen.executor.signals`) and kills
its workers before the error propagates. `shared_pool` lends one set of workers to a block,
`helper` one worker that runs jobs while its block goes on; `deadline` and `reporting` carry
the parent's time limit and progress listener into its workers.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import threading
import time
from collections.abc import Callable, Iterator
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures import TimeoutError as FutureTimeout
from typing import Any

from printgen.errors import TimeLimitError
from printgen.executor import start
from printgen.executor.signals import signals_deferred, unblock_signals
from printgen.executor.start import WATCH_THREAD, Platform
from printgen.trace import span, traced_job

PR_SET_PDEATHSIG = 1  # linux/prctl.h
READER_JOIN_S = 5.0  # the progress reader has only the queued reports left to pass on
STOP_JOIN_S = 5.0  # killed workers and their pool's manager thread end at once


def init_worker(plat: Platform, sink: Any = None, at: float | None = None) -> None:
    """Pool initializer: die with the parent, leave signals to the parent, report progress to
    `sink` (the parent's queue, or None), keep the parent's deadline `at` (`deadline`)."""
    global _sink, _deadline, _shared, _listener
    start.inherit(plat)
    _sink, _deadline = sink, at
    _shared, _listener = None, None  # a forked worker's copies of its parent's
    for s in plat.signals:
        signal.signal(s, signal.SIG_IGN)
    unblock_signals()  # blocked since it started (`_Workers`): ignored now, a pending one dropped
    parent = multiprocessing.parent_process()
    if plat.pdeathsig:
        _die_with_parent_linux()
    if not plat.pdeathsig or (parent is not None and os.getppid() != parent.pid):
        # the kernel's signal follows the process that forked this one: under `forkserver`
        # that is the fork server, which outlives a SIGKILLed parent while workers hold it
        _watch_parent()
    if parent is not None and not parent.is_alive():  # it died before the guard took effect
        os._exit(1)


def _die_with_parent_linux() -> None:
    import ctypes

    with contextlib.suppress(OSError, AttributeError):
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)


def _watch_parent() -> None:
    """Where no parent-death signal exists: a daemon thread waits on the parent's sentinel
    (closed by the OS when the parent dies, however it dies) and ends this worker."""
    parent = multiprocessing.parent_process()
    if parent is None:
        return

    def watch() -> None:
        parent.join()
        os._exit(1)

    threading.Thread(target=watch, name=WATCH_THREAD, daemon=True).start()


_listener: Callable[[str, float, float], None] | None = None  # set by `reporting`
_sink: Any = None  # in a job: the queue (workers) or the listener (serial) to report to


@contextlib.contextmanager
def reporting(listener: Callable[[str, float, float], None]) -> Iterator[None]:
    """Within the block, `report_progress(task, done, total)` calls from jobs run by
    `run_jobs` reach `listener` (in the parent, from a helper thread when jobs run in
    workers). Used by `make` for its per-load-level progress."""
    global _listener
    previous, _listener = _listener, listener
    try:
        yield
    finally:
        _listener = previous


_deadline: float | None = None  # time.time() past which `check_deadline` raises (handed to
# workers by `init_worker`: set before their pool is made)


@contextlib.contextmanager
def deadline(at: float | None) -> Iterator[None]:
    """Within the block, `check_deadline` raises TimeLimitError once time.time() passes `at`
    (None: no limit), in this process and in workers whose pool is made inside the block."""
    global _deadline
    previous, _deadline = _deadline, at
    try:
        yield
    finally:
        _deadline = previous


def seconds_left() -> float | None:
    """Seconds until the deadline of `deadline` (None without one; may be negative)."""
    return None if _deadline is None else _deadline - time.time()


def check_deadline(what: str) -> None:
    """Raise TimeLimitError naming `what` when the deadline of `deadline` has passed."""
    left = seconds_left()
    if left is not None and left < 0:
        raise TimeLimitError(f"{what}: past the time limit")


def _result(f: Future) -> Any:
    """A job's result, waited for no longer than the deadline (`deadline`)."""
    left = seconds_left()
    try:
        return f.result(timeout=None if left is None else max(left, 0.0))
    except FutureTimeout as exc:
        raise TimeLimitError("a worker's job: past the time limit") from exc


def collect(futures: list[Future]) -> list:
    """The futures' results, each waited for no longer than the deadline (`deadline`)."""
    return [_result(f) for f in futures]


def report_progress(task: str, done: float, total: float) -> None:
    """From inside a job: `task` has reached `done` of `total` (e.g. load level 0.35 of 1.1).
    A no-op unless the caller of `run_jobs` is listening."""
    sink = _sink
    if sink is None:
        return
    with contextlib.suppress(Exception):  # progress must never break the work
        sink(task, done, total) if callable(sink) else sink.put((task, done, total))


def _relay() -> Any:
    """In a worker reporting to its parent's queue: that queue, for the workers it starts
    (their reports go straight to the first process); else None."""
    return _sink if _sink is not None and not callable(_sink) else None


def _drain(queue: Any, listener: Callable[[str, float, float], None]) -> None:
    while (item := queue.get()) is not None:
        with contextlib.suppress(Exception):
            listener(*item)


def run_jobs(jobs: list[tuple]) -> list:
    """Run each (fn, args, kwargs) and return the results in order: in worker processes when
    the machine has two cores or more (the jobs are independent; the results are identical
    either way), else one after the other. PRINTGEN_SERIAL=1 forces serial runs.

    On any exception or signal in the parent the workers are killed before it propagates.
    """
    if _shared is not None:  # within `shared_pool`: its workers
        return collect([_shared.submit(fn, *args, **kw) for fn, args, kw in jobs])
    workers = min(len(jobs), start.cores())
    if workers < 2 or os.environ.get("PRINTGEN_SERIAL"):
        return [_done(*traced_job(*j)).result() for j in jobs]
    with span(f"pool of {workers} for {len(jobs)} jobs"):
        return _in_pool(jobs, workers)


def submit_jobs(jobs: list[tuple]) -> list[Future]:
    """Start each (fn, args, kwargs) and return their futures (`collect` waits for them):
    within `shared_pool` on its workers, without waiting; else `run_jobs` runs them now."""
    if _shared is not None:
        return [_shared.submit(fn, *args, **kw) for fn, args, kw in jobs]
    out: list[Future] = []
    for result in run_jobs(jobs):
        out.append(Future())
        out[-1].set_result(result)
    return out


def _in_pool(jobs: list[tuple], workers: int) -> list:
    w = _Workers(workers)
    try:
        futures = [w.submit(fn, *args, **kw) for fn, args, kw in jobs]
        results = [_result(f) for f in futures]
    except BaseException:
        stop(w.pool)
        raise
    w.pool.shutdown(wait=True)
    w.end_reports()
    return results


class _Workers:
    """`workers` processes started by `init_worker` (they die with this process and leave
    signals to it), their jobs traced (`printgen.trace`) and their progress passed on to the
    listener (`reporting`) by a reader thread, or straight to the first process's queue when
    this process is itself a worker reporting there (`_relay`)."""

    def __init__(self, workers: int) -> None:
        plat = start.platform()
        method = start.start_method(plat)
        start.check_main_guard(method)
        start.servers_for(method)
        ctx = multiprocessing.get_context(method)
        self.queue = ctx.SimpleQueue() if _listener else None
        self.reader: threading.Thread | None = None
        self.pool = ProcessPoolExecutor(max_workers=workers, mp_context=ctx,
                                        initializer=init_worker,
                                        initargs=(plat, self.queue or _relay(), _deadline))

    def submit(self, fn: Callable, /, *args: Any, **kwargs: Any) -> Future:
        fn, args, kwargs = traced_job(fn, args, kwargs)
        # the workers a submit starts begin with the stop signals blocked: one sent to the
        # group before `init_worker` ignores them would stop a worker with a traceback
        with start.watch_is_safe(), signals_deferred():
            f = self.pool.submit(fn, *args, **kwargs)
        if self.queue is not None and self.reader is None:
            # started once the workers are (a forking pool starts them all at its first job):
            # fork only a one-thread process
            self.reader = threading.Thread(target=_drain, args=(self.queue, _listener),
                                           daemon=True)
            self.reader.start()
        return f

    def end_reports(self) -> None:
        """The workers are done: pass on the reports left, then end the reader."""
        if self.reader is not None and self.queue is not None:
            self.queue.put(None)
            self.reader.join(timeout=READER_JOIN_S)


class Pool:
    """Worker processes for the jobs of a block (`shared_pool`): `submit` starts a job now and
    returns its Future (`collect` waits for futures within the deadline). With one core or
    PRINTGEN_SERIAL=1, `submit` runs the job at once (its Future is done)."""

    def __init__(self, workers: int) -> None:
        serial = workers < 2 or os.environ.get("PRINTGEN_SERIAL")
        self.workers = None if serial else _Workers(workers)
        self.size = 1 if serial else workers  # processes the jobs run on at once

    def submit(self, fn: Callable, /, *args: Any, **kwargs: Any) -> Future:
        if self.workers is None:
            return _done(*traced_job(fn, args, kwargs))
        return self.workers.submit(fn, *args, **kwargs)

    def close(self) -> None:
        if self.workers is not None:
            self.workers.pool.shutdown(wait=True)
            self.workers.end_reports()


def _done(fn: Callable, args: tuple, kwargs: dict) -> Future:
    """A Future holding fn(*args, **kwargs), run here, its progress reported to this
    process's listener or, in a worker, its parent's queue (its error raised here)."""
    global _sink
    f: Future = Future()
    previous, _sink = _sink, _listener or _sink  # in a worker: its parent's queue
    try:
        f.set_result(fn(*args, **kwargs))
    finally:
        _sink = previous
    return f


_shared: Pool | None = None  # set by `shared_pool` (None in every worker: `init_worker`)


@contextlib.contextmanager
def shared_pool(workers: int | None = None) -> Iterator[Pool]:
    """One set of worker processes (`workers`, default: the cores) for the block: its jobs
    submitted as their inputs are ready (`Pool.submit`), and every `run_jobs` of the block in
    this process, start on them instead of on pools of their own, so that a core freed by one
    sweep takes the next job at once. On any exception or signal the workers are killed
    before it propagates."""
    global _shared
    previous = _shared
    pool = Pool(start.cores() if workers is None else workers)
    _shared = pool
    try:
        with span("shared pool"):
            yield pool
    except BaseException:
        if pool.workers is not None:
            stop(pool.workers.pool)
        raise
    finally:
        _shared = previous
    pool.close()


class Helper(_Workers):
    """One worker process that runs the jobs submitted to it in order (see `helper`)."""

    def __init__(self) -> None:
        super().__init__(1)
        self.futures: list[Future] = []

    def submit(self, fn: Callable, /, *args: Any, **kwargs: Any) -> Future:
        """Start `fn(*args, **kwargs)` there; `.result()` collects it (or raises its error)."""
        self.futures.append(super().submit(fn, *args, **kwargs))
        return self.futures[-1]


@contextlib.contextmanager
def helper() -> Iterator[Helper]:
    """A `Helper` for the block: one worker process for jobs that run while the block goes
    on. The worker lives like `run_jobs`' workers (dies with its parent, leaves signals to
    it) and may call `run_jobs` itself: its workers die with it. On any exception or signal in
    the block, or a job left uncollected, the worker is killed before the block's exit
    completes."""
    h = Helper()
    try:
        yield h
    except BaseException:
        stop(h.pool)
        raise
    if all(f.done() for f in h.futures):
        h.pool.shutdown(wait=True)
    else:
        stop(h.pool)
    h.end_reports()


def stop(pool: ProcessPoolExecutor) -> None:
    """Kill the pool's workers now and reap them (no waiting for running jobs), and let its
    manager thread end: concurrent.futures' exit hook waits for it, and it may be stuck
    reading the rest of a result a killed worker was writing (this process holds the pipe's
    other end too: no end of file comes), so that end is closed once the workers are dead.
    (The manager thread then closes the jobs' pipe itself, which frees its feeder.) No public
    API for any of it."""
    procs = list((getattr(pool, "_processes", None) or {}).values())
    manager = getattr(pool, "_executor_manager_thread", None)  # (shutdown forgets them)
    results = getattr(getattr(pool, "_result_queue", None), "_writer", None)
    for p in procs:
        with contextlib.suppress(Exception):
            p.kill()
    for p in procs:
        with contextlib.suppress(Exception):
            p.join(timeout=STOP_JOIN_S)
    pool.shutdown(wait=False, cancel_futures=True)
    if results is not None:  # only this thread uses that end here: closed once
        with contextlib.suppress(Exception):
            results.close()
    if manager is not None and manager is not threading.current_thread():
        manager.join(timeout=STOP_JOIN_S)
