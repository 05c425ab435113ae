"""Worker processes (printgen/executor/local.py): they die with their parent, leave signals to it,
are killed when the parent stops, and pass progress reports back."""

from __future__ import annotations

import ctypes
import os
import signal
import threading
import time
from pathlib import Path

import pytest

from printgen.executor import local as workers
from printgen.executor import signals, start
from printgen.run.budget import level_bars

PR_GET_PDEATHSIG = 2  # linux/prctl.h
GONE_WITHIN_S = 5.0  # issue 16: no worker left 5 s after the parent stops
SLEEP_S = 60.0  # a job far longer than the test

two_cores = pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="workers need 2 cores")


def worker_state() -> tuple[int, object]:
    sig = ctypes.c_int(0)
    ctypes.CDLL(None, use_errno=True).prctl(PR_GET_PDEATHSIG, ctypes.byref(sig), 0, 0, 0)
    return sig.value, signal.getsignal(signal.SIGINT)


def reporting_job(name: str) -> str:
    for level in (0.5, 1.0, 1.1):
        workers.report_progress(name, level, 1.1)
    return name


def sleeper(pid_file: str) -> None:
    Path(pid_file).write_text(str(os.getpid()))
    time.sleep(SLEEP_S)


@two_cores
def test_workers_die_with_the_parent_and_ignore_signals(monkeypatch):
    monkeypatch.delenv("PRINTGEN_SERIAL", raising=False)
    states = workers.run_jobs([(worker_state, (), {}), (worker_state, (), {})])
    assert states == [(signal.SIGKILL, signal.SIG_IGN)] * 2


@pytest.mark.parametrize("serial", ["", "1"])
def test_progress_reaches_the_listener(monkeypatch, serial):
    monkeypatch.delenv("PRINTGEN_SERIAL", raising=False)
    if serial:
        monkeypatch.setenv("PRINTGEN_SERIAL", serial)
    got = []
    with workers.reporting(lambda *a: got.append(a)):
        assert workers.run_jobs([(reporting_job, ("a",), {}), (reporting_job, ("b",), {})]) == [
            "a", "b"]
    assert sorted(got) == sorted((n, lv, 1.1) for n in "ab" for lv in (0.5, 1.0, 1.1))
    workers.report_progress("after", 1.0, 1.0)  # nobody listens: a no-op
    assert len(got) == 6


def test_level_bars_text():
    lines = []
    with level_bars(lines.append):
        workers.run_jobs([(reporting_job, ("Barrier: prototype",), {})])
    assert lines[-1] == "verification: prototype [" + "#" * 20 + "] h/h_B 1.10/1.1"
    assert lines[0].startswith("verification: prototype [#########.")


@two_cores
def test_a_signal_in_the_parent_kills_the_workers(tmp_path, monkeypatch):
    monkeypatch.delenv("PRINTGEN_SERIAL", raising=False)
    files = [tmp_path / "a.pid", tmp_path / "b.pid"]

    def term_when_started():
        while not all(f.exists() and f.read_text() for f in files):
            time.sleep(0.05)
        os.kill(os.getpid(), signal.SIGTERM)

    threading.Thread(target=term_when_started, daemon=True).start()
    t0 = time.monotonic()
    with pytest.raises(signals.Interrupted) as exc, signals.signals_raise():
        workers.run_jobs([(sleeper, (str(f),), {}) for f in files])
    assert exc.value.exit_code == 143 and time.monotonic() - t0 < SLEEP_S
    pids = [int(f.read_text()) for f in files]
    deadline = time.monotonic() + GONE_WITHIN_S
    while any(Path(f"/proc/{p}").exists() and "Z" not in _state(p) for p in pids):
        assert time.monotonic() < deadline, "workers still running"
        time.sleep(0.1)


def _state(pid: int) -> str:
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return "Z"
    return text[text.rindex(")") + 2]


def _how_it_starts_workers() -> tuple[str, list[str], list[str]]:
    """In a helper: its start method, its threads, and how its own workers started."""
    names = [t.name for t in threading.enumerate()]
    return start.start_method(), names, workers.run_jobs([(start.start_method, (), {})] * 2)


@two_cores
@pytest.mark.skipif(not start.SYSTEM.startswith("linux"), reason="fork: Linux only")
def test_a_helper_started_by_the_fork_server_forks_its_own_workers(monkeypatch):
    """Under the command line a spinner thread runs beside make, so its helper starts by the
    fork server and watches its parent from a thread; the helper's workers (the sweeps', the
    figures') still start by fork, with its imports, not from a fork server of their own."""
    monkeypatch.delenv("PRINTGEN_SERIAL", raising=False)
    stop = threading.Event()
    spinner = threading.Thread(target=stop.wait)
    spinner.start()
    try:
        assert start.start_method() == "forkserver"
        with workers.helper() as h:
            method, threads, theirs = h.submit(_how_it_starts_workers).result()
    finally:
        stop.set()
        spinner.join()
    assert start.WATCH_THREAD in threads and method == "fork"
    assert theirs == ["fork", "fork"]  # in the helper's workers: no watch, one thread


def pid_of(_k: int) -> int:
    return os.getpid()


@pytest.mark.parametrize("serial", ["", "1"])
def test_shared_pool_runs_every_job_of_the_block_on_its_workers(monkeypatch, serial):
    """Within `shared_pool`, submitted jobs and those of `run_jobs` run on the same workers
    (PRINTGEN_SERIAL=1 or one core: here, at once), results in order; the workers are gone
    after the block."""
    monkeypatch.setenv("PRINTGEN_SERIAL", serial)
    with workers.shared_pool(2) as pool:
        first = pool.submit(pid_of, 0)
        later = workers.run_jobs([(pid_of, (k,), {}) for k in range(4)])
        pids = {*workers.collect([first]), *later}
    if serial or start.cores() < 2:
        assert first.done() and pids == {os.getpid()}
    else:
        assert os.getpid() not in pids and len(pids) <= 2
    assert workers.run_jobs([(pid_of, (0,), {})])[0] not in pids - {os.getpid()}


def scaled(factor: int, k: int) -> tuple[int, int]:
    return factor * k, os.getpid()


@pytest.mark.parametrize("serial", [True, False])
def test_map_then_starts_the_second_tasks_from_the_first_result(monkeypatch, serial):
    """`Runner.map_then`: the tasks `then` makes of the first item's result run too (on the
    local pool, queued while the first map still runs), both lists of results in order, the
    same serially and on two workers."""
    from printgen.executor import open_runner

    monkeypatch.delenv("PRINTGEN_SERIAL", raising=False)
    seen = []

    def then(first: tuple[int, int]) -> tuple:
        seen.append(first[0])
        return scaled, [1, 2, 3], first[0]

    with open_runner(serial=serial, workers=None if serial else min(2, start.cores())) as run:
        a, b = run.map_then(scaled, [5, 6, 7], then, shared=10)
    assert seen == [50]
    assert [x for x, _ in a] == [50, 60, 70] and [x for x, _ in b] == [50, 100, 150]
    pids = {p for _, p in a + b}
    assert pids == {os.getpid()} if serial or start.cores() < 2 else os.getpid() not in pids


def test_preload_is_a_no_op_where_workers_fork(monkeypatch):
    """Only a fork server imports ahead: under `fork` nothing is started."""
    started = []
    monkeypatch.setattr(start, "start_method", lambda plat=None: "fork")
    monkeypatch.setattr("multiprocessing.forkserver.ensure_running", lambda: started.append(1))
    start.preload(["json"])
    assert started == []
