"""printgen on a platform that is not Linux (issue 21): no fork, no prctl, no SIGHUP, no fcntl.

The platform is simulated on this Linux machine: those calls are removed (monkeypatched, or
blocked in a child interpreter) and printgen must import, answer --help, start its workers by
`spawn` with a watchdog in place of the parent-death signal, and run `make` end to end,
writing the same files as on Linux.
"""

from __future__ import annotations

import json
import multiprocessing
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest
from conftest import alive
from proto_files import REALISTIC

import printgen.run.make as make_mod
from printgen.cli import main
from printgen.executor import local as workers
from printgen.executor import start
from printgen.outputs import folder_files, lock
from printgen.report.jsonout import dumps

ROOT = Path(__file__).resolve().parents[1]
LINUX_ONLY = ("fcntl", "termios", "resource", "pty", "tty", "grp", "pwd")  # absent on Windows
GONE_WITHIN_S = 10.0  # the watchdog ends an orphaned worker at once; slack for a loaded CI
START_WITHIN_S = 120.0  # spawned workers import numpy and printgen: slow on a loaded machine

# Run first in a child interpreter: the Linux-only modules are absent (every finder says it
# has none, so `importlib.util.find_spec` gives None and `import` raises ModuleNotFoundError),
# os has no fork and signal no SIGHUP or SIGKILL, as on Windows.
SIMULATE = textwrap.dedent(f"""
    import os, signal, sys
    class Hide:
        def __init__(self, inner):
            self.inner = inner
        def find_spec(self, name, path=None, target=None):
            if name.split(".")[0] in {LINUX_ONLY!r}:
                return None
            return self.inner.find_spec(name, path, target)
        def __getattr__(self, attr):
            return getattr(self.inner, attr)
    sys.meta_path[:] = [Hide(f) for f in sys.meta_path]
    for mod in {LINUX_ONLY!r}:
        sys.modules.pop(mod, None)
    for obj, name in ((os, "fork"), (os, "forkpty"), (os, "register_at_fork"),
                      (signal, "SIGHUP"), (signal, "SIGKILL")):
        if hasattr(obj, name):
            delattr(obj, name)
""")


def simulated(code: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run([sys.executable, "-c", SIMULATE + textwrap.dedent(code)], check=False,
                          capture_output=True, text=True, env=env, cwd=ROOT, timeout=300)


@pytest.mark.slow
def test_import_help_and_version_need_nothing_linux_only():
    r = simulated("""
        import printgen
        from printgen.cli import main
        main(["--version"])  # argparse prints it and exits 0
    """)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == f"printgen {__import__('printgen').__version__}"
    r = simulated("""
        from printgen.cli import main
        main(["--help"])
    """)
    assert r.returncode == 0, r.stderr
    assert "make" in r.stdout and "example" in r.stdout
    loaded = simulated(f"""
        import sys
        from printgen.cli import build_parser
        from printgen.outputs import lock
        build_parser([])
        print(sorted(m for m in {LINUX_ONLY!r} if m in sys.modules), lock.BACKEND)
    """)
    assert loaded.returncode == 0 and loaded.stdout.split() == ["[]", "exclusive"], loaded.stderr


def simulate_windows(monkeypatch) -> list[Path]:
    """In this process: no fork (spawn only), no prctl (start.SYSTEM), no SIGHUP, no fcntl
    (the output lock's `exclusive` backend; flock fails the test). The returned list collects
    the folders locked the exclusive way."""
    locked: list[Path] = []
    exclusive = lock._exclusive

    def no_flock(dest: Path, path: Path) -> int:
        raise AssertionError(f"flock used for {dest} on a platform without fcntl")

    monkeypatch.setattr(lock, "BACKEND", "exclusive")
    monkeypatch.setattr(lock, "_flock", no_flock)
    monkeypatch.setattr(lock, "_exclusive",
                        lambda dest, path: locked.append(dest) or exclusive(dest, path))
    monkeypatch.setattr(start, "SYSTEM", "win32")
    monkeypatch.setattr(multiprocessing, "get_all_start_methods", lambda: ["spawn"])
    monkeypatch.delattr(os, "fork")
    monkeypatch.delattr(signal, "SIGHUP")
    monkeypatch.delattr(os, "O_NOFOLLOW")
    monkeypatch.setattr(lock, "NOFOLLOW", 0)
    monkeypatch.delenv("PRINTGEN_SERIAL", raising=False)
    return locked


def what_a_worker_sees() -> tuple:
    return (start.platform(), start.start_method(), signal.getsignal(signal.SIGINT),
            [t.name for t in __import__("threading").enumerate()])


@pytest.mark.slow
@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="workers need 2 cores")
def test_workers_on_a_platform_without_fork_or_prctl(monkeypatch):
    simulate_windows(monkeypatch)
    plat = start.platform()
    assert plat.signals == (signal.SIGINT, signal.SIGTERM) and not plat.pdeathsig
    assert start.start_method() == "spawn"
    seen = workers.run_jobs([(what_a_worker_sees, (), {})] * 2)
    for got_plat, method, sigint, threads in seen:  # workers of workers: spawn too
        assert (got_plat, method, sigint) == (plat, "spawn", signal.SIG_IGN)
        assert "printgen-parent-watch" in threads


ORPHAN = """
    import multiprocessing, sys, time
    from pathlib import Path
    from printgen.executor import local as workers, start
    from test_portable import sleeper
    start.SYSTEM = "win32"
    multiprocessing.get_all_start_methods = lambda: ["spawn"]
    workers.run_jobs([(sleeper, (f,), {}) for f in sys.argv[1:]])
"""


def sleeper(pid_file: str) -> None:
    Path(pid_file).write_text(str(os.getpid()))
    time.sleep(START_WITHIN_S * 2)


@pytest.mark.slow
@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="workers need 2 cores")
def test_the_watchdog_ends_workers_whose_parent_was_killed(tmp_path):
    """Without PR_SET_PDEATHSIG a worker ends itself when its parent dies (SIGKILL)."""
    files = [str(tmp_path / "a.pid"), str(tmp_path / "b.pid")]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), str(ROOT / "tests")])}
    env.pop("PRINTGEN_SERIAL", None)
    parent = subprocess.Popen([sys.executable, "-c", textwrap.dedent(ORPHAN), *files], env=env)
    try:
        deadline = time.monotonic() + START_WITHIN_S
        while not all(Path(f).exists() and Path(f).read_text() for f in files):
            assert parent.poll() is None and time.monotonic() < deadline, "workers never ran"
            time.sleep(0.1)
    finally:
        parent.kill()
        parent.wait()
    pids = [int(Path(f).read_text()) for f in files]
    deadline = time.monotonic() + GONE_WITHIN_S
    while any(alive(p) for p in pids):
        assert time.monotonic() < deadline, f"orphaned workers {pids} still running"
        time.sleep(0.1)


@pytest.mark.slow
@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="workers need 2 cores")
def test_make_on_a_platform_without_fork_prctl_sighup_fcntl_gives_the_same_files(
        made_1_40, tmp_path, monkeypatch):
    """`make` end to end where there is no fork, prctl, SIGHUP or fcntl: the verification's
    helper process and its pool start by spawn, the output folder is locked the exclusive
    way, `printgen check` (the command line's signal handling without SIGHUP) passes, and every
    file but the volatile timings.json is byte-identical to the shared run's (made on Linux,
    with fork), its `--json` record too but for "timings": the same input gives the same files
    on any platform and in any run. (One second whole make of the 1:40 example for both
    checks; they were two runs, issue 24.)"""
    made, first = made_1_40
    locked = simulate_windows(monkeypatch)
    asked: list[str] = []
    get_context = multiprocessing.get_context
    monkeypatch.setattr(multiprocessing, "get_context",
                        lambda method=None: asked.append(method) or get_context(method))
    out = tmp_path / "o"
    again = make_mod.make(REALISTIC, 40, out)
    assert asked and set(asked) == {"spawn"}  # the verification's helper process and its pool
    assert locked == [out] and not lock.lock_path(out).exists()  # lock file created, removed
    assert main(["check", str(out)]) == 0
    names = folder_files(first)
    assert names == folder_files(out)
    volatile = json.loads((first / "manifest.json").read_text())["volatile"]
    assert volatile == ["timings.json"]
    for name in set(names) - set(volatile):
        assert (out / name).read_bytes() == (first / name).read_bytes(), name
    one, two = make_mod.json_output(made), make_mod.json_output(again)
    assert one.pop("timings") != two.pop("timings")  # wall-clock times differ
    assert dumps(one) == dumps(two)


def test_files_are_written_without_o_nofollow(tmp_path, monkeypatch, capsys):
    """init, example --out and calibrate's profile write (each through outputs.write_bytes)
    on a platform without os.O_NOFOLLOW."""
    from printgen.cli import main

    simulate_windows(monkeypatch)
    assert main(["init", str(tmp_path / "proto.toml")]) == 0
    assert main(["example", "paper_1_40", "--out", str(tmp_path / "ex")]) == 0
    from printgen.outputs.files import write_text

    assert write_text(tmp_path / "materials" / "x.toml", "a = 1\n").read_text() == "a = 1\n"
    assert "internal error" not in capsys.readouterr().err


@pytest.mark.parametrize("guarded", [False, True])
def test_a_script_without_a_main_guard_is_told_so_where_workers_run_it_again(tmp_path, guarded):
    """Under spawn (macOS, Windows) each worker runs the main script again: without `if
    __name__ == "__main__":` its calls would run in every worker and break the pool, which
    read as "a worker died / out of memory"; the check names the script and the fix."""
    body = 'import printgen.executor.start as s\ns.check_main_guard("spawn")\nprint("ok")\n'
    if guarded:
        body = 'if __name__ == "__main__":\n' + textwrap.indent(body, "    ")
    script = tmp_path / "my_run.py"
    script.write_text(body)
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    if guarded:
        assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr
    else:
        assert done.returncode == 1 and "my_run.py runs printgen's parallel work" in done.stderr
        assert 'if __name__ == "__main__":' in done.stderr
