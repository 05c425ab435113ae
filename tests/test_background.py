"""`make`'s verification ahead of the other steps: `workers.helper` (one worker process whose
jobs may run `run_jobs` themselves, killed with everything under it when the block fails),
`signals_deferred` (a signal during trimesh's imports is not swallowed), and the same
verification sections and record whether the verification ran in the helper or in its step."""

from __future__ import annotations

import contextlib
import os
import signal
import threading
import time
from pathlib import Path

import pytest
from conftest import alive

import printgen.run.make as make_mod
from printgen.executor import local as workers
from printgen.executor import signals
from printgen.report.jsonout import dumps
from printgen.run.options import RunOptions
from printgen.run.provenance import split_timings

GONE_WITHIN_S = 5.0  # issue 16: no worker left 5 s after the parent stops
SLEEP_S = 60.0  # a job far longer than the test

two_cores = pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="workers need 2 cores")


def square(x: int) -> int:
    return x * x


def nested(n: int) -> tuple[int, list[int]]:
    """The worker's pid and the results of its own run_jobs."""
    return os.getpid(), workers.run_jobs([(square, (k,), {}) for k in range(n)])


def reporting_pool(names: list[str]) -> list[int]:
    """Jobs on a shared pool and on a pool of run_jobs, each reporting its progress."""
    with workers.shared_pool() as pool:
        first = workers.collect([pool.submit(reported, n) for n in names[:1]])
        return first + workers.run_jobs([(reported, (n,), {}) for n in names[1:]])


def reported(name: str) -> int:
    workers.report_progress(name, 1.0, 2.0)
    return os.getpid()


def failing() -> None:
    raise ValueError("from the worker")


def sleeper_tree(folder: str) -> None:
    """Write this worker's pid, then sleep in two workers of its own that write theirs."""
    Path(folder, "top.pid").write_text(str(os.getpid()))
    workers.run_jobs([(_sleep, (str(Path(folder, f"{k}.pid")),), {}) for k in range(2)])


def _sleep(pid_file: str) -> None:
    Path(pid_file).write_text(str(os.getpid()))
    time.sleep(SLEEP_S)


@two_cores
def test_progress_of_a_helpers_workers_reaches_the_listener(monkeypatch):
    """A long make's per-level bars: the sweeps run in the helper's workers, their reports
    reach the listener of the process that started the helper (issue 28: the helper in every
    make)."""
    monkeypatch.delenv("PRINTGEN_SERIAL", raising=False)
    heard: list[tuple[str, float, float]] = []
    with workers.reporting(lambda *item: heard.append(item)), workers.helper() as h:
        pids = h.submit(reporting_pool, ["a", "b", "c"]).result()
    assert os.getpid() not in pids
    assert sorted(heard) == [("a", 1.0, 2.0), ("b", 1.0, 2.0), ("c", 1.0, 2.0)]


@two_cores
def test_helper_runs_jobs_that_have_workers_of_their_own(monkeypatch):
    monkeypatch.delenv("PRINTGEN_SERIAL", raising=False)
    with workers.helper() as h:
        pid, squares = h.submit(nested, 3).result()
        again, cubes = h.submit(nested, 2).result()
    assert pid != os.getpid() and again == pid  # one process, job after job
    assert squares == [0, 1, 4] and cubes == [0, 1]
    with pytest.raises(ValueError, match="from the worker"), workers.helper() as h:
        h.submit(failing).result()


@two_cores
def test_a_failure_in_the_block_kills_the_worker_and_its_workers(tmp_path, monkeypatch):
    monkeypatch.delenv("PRINTGEN_SERIAL", raising=False)
    files = [tmp_path / n for n in ("top.pid", "0.pid", "1.pid")]
    t0 = time.monotonic()
    with pytest.raises(RuntimeError, match="parent failed"), workers.helper() as h:
        h.submit(sleeper_tree, str(tmp_path))
        while not all(f.exists() and f.read_text() for f in files):
            assert time.monotonic() - t0 < SLEEP_S / 2, "the workers never started"
            time.sleep(0.05)
        raise RuntimeError("parent failed")
    pids = [int(f.read_text()) for f in files]
    deadline = time.monotonic() + GONE_WITHIN_S
    while any(alive(p) for p in pids):
        assert time.monotonic() < deadline, "workers still running"
        time.sleep(0.1)


def test_signals_deferred_holds_a_signal_until_the_block_ends():
    reached = []
    with pytest.raises(signals.Interrupted) as exc, signals.signals_raise(), \
            signals.signals_deferred():
        try:
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(0.2)  # the handler has run by now: it only held the signal
        except BaseException:  # noqa: BLE001 (what trimesh's imports do)
            pytest.fail("the signal reached the block")
        reached.append("end of block")
    assert reached == ["end of block"] and exc.value.signum == signal.SIGTERM


def test_signals_deferred_outside_the_main_thread_is_a_no_op():
    done = []
    t = threading.Thread(target=lambda: done.append(_deferred_in_thread()))
    t.start()
    t.join()
    assert done == [True]


def _deferred_in_thread() -> bool:
    with signals.signals_deferred():
        return True


@pytest.mark.slow
@two_cores
def test_verification_in_the_helper_equals_the_verification_step(made_simple_drag, tmp_path,
                                                                  monkeypatch):
    """Same report blocks and record (times aside) from the helper as from the step itself
    (the shared run, made inline with PRINTGEN_SERIAL=1 and no helper)."""
    monkeypatch.delenv("PRINTGEN_SERIAL", raising=False)
    inline, _, path = made_simple_drag
    steps = [s for s in make_mod.default_steps() if s[1] is make_mod.verify_step]
    started = []
    monkeypatch.setattr(make_mod, "helper", _spy(make_mod.helper, started))
    ahead = make_mod.make(path, 40, tmp_path / "ahead", steps=steps,
                          options=RunOptions(load="drag"))
    assert started == ["sweeps_and_advice", "draw_all"]  # the figures: drawn in its workers
    assert ahead.report.blocks == inline.report.blocks
    assert (dumps(split_timings(ahead.record["verification"])[0])
            == dumps(split_timings(inline.record["verification"])[0]))


def _spy(helper, calls: list):
    """`helper` whose jobs' names go to `calls`."""
    @contextlib.contextmanager
    def spied():
        with helper() as h:
            submit = h.submit

            def named(fn, /, *args, **kwargs):
                job = args[0] if fn is make_mod.timed else fn  # timed(job, ...)
                calls.append(job.__name__)
                return submit(fn, *args, **kwargs)

            h.submit = named
            yield h
    return spied
