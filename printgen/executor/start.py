"""How worker processes start on this platform: the start method (`fork`, `forkserver` or
`spawn`), what the platform offers them (`Platform`, found once in the first process and
handed to every worker, so workers of workers use the same), the fork server started early
with the jobs' modules (`preload`, `warm_up`) and multiprocessing's resource tracker quietened
(`quiet_tracker`), both started with the stop signals blocked (`servers_for`: they never see
the group's signals and end when the processes they serve end). Workers start by `fork` where
it exists and is safe (Linux, a parent running no other Python thread), else by `forkserver`
(POSIX) or `spawn` (Windows, macOS).
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import re
import sys
import threading
import warnings
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

from printgen.errors import InputError
from printgen.executor.signals import handled_signals, signals_deferred

SYSTEM = sys.platform  # "linux", "darwin", "win32", ...
WATCH_THREAD = "printgen-parent-watch"  # the thread of `local._watch_parent`
TRACKER_WARNING = "ignore:resource_tracker:UserWarning"  # a -W option (sys.warnoptions)


@dataclass(frozen=True)
class Platform:
    """What the platform offers worker processes: its name (`sys.platform`), multiprocessing's
    start methods, and the stop signals it defines (numbers)."""

    system: str
    start_methods: tuple[str, ...]
    signals: tuple[int, ...]

    @property
    def pdeathsig(self) -> bool:
        """The kernel can kill a worker whose parent dies (Linux prctl)."""
        return self.system.startswith("linux")


_inherited: Platform | None = None  # in a worker: the first process's Platform (`inherit`)


def inherit(plat: Platform) -> None:
    """In a worker (`local.init_worker`): use the first process's Platform from now on."""
    global _inherited
    _inherited = plat


def platform() -> Platform:
    """This platform's offer (in a worker: the one its first ancestor found)."""
    if _inherited is not None:
        return _inherited
    return Platform(SYSTEM, tuple(multiprocessing.get_all_start_methods()), handled_signals())


def start_method(plat: Platform | None = None) -> str:
    """`fork` on Linux while this process runs no other Python thread (forking a threaded
    process can deadlock the child on a lock another thread held, and Python 3.12+ warns: a
    notebook kernel, a Dask client) but this module's parent watch (`_watch_parent`: it only
    waits on a file descriptor, holding no lock, and the child does not inherit it); else
    `forkserver` where it exists, except on macOS, whose system libraries are unsafe after
    fork; else `spawn` (Windows). A forked worker starts with its parent's imports; one of
    the fork server imports printgen, numpy and scipy again (about 1 s of CPU each)."""
    plat = plat or platform()
    linux = plat.system.startswith("linux")
    if "fork" in plat.start_methods and linux and _one_thread():
        return "fork"
    if "forkserver" in plat.start_methods and plat.system != "darwin":
        return "forkserver"
    return "spawn"


def preload(modules: Iterable[str]) -> None:
    """Where workers start by `forkserver` (`start_method`: the process runs a thread, such as
    the command line's spinner), have multiprocessing's fork server import `modules` (what the
    run's jobs need) and start it now, so that it imports them while this process goes on: every
    worker is then forked from it with them imported, a pool ready in ~0.05 s instead of the
    3 to 5 s of importing numpy, scipy, printgen and matplotlib again in each worker (measured
    on 2 shared cores). The first call's modules stay: the server lives as long as this
    process. Under `fork` and `spawn` nothing is done."""
    if start_method() != "forkserver":
        return
    multiprocessing.get_context("forkserver").set_forkserver_preload(list(modules))
    servers_for("forkserver")


def servers_for(method: str) -> None:
    """Start what workers started by `method` need, if not running: multiprocessing's resource
    tracker (`quiet_tracker`; not for `fork`) and, for `forkserver`, the fork server (with the
    modules of `preload`), each with the stop signals blocked (`signals.signals_deferred`),
    which they keep: a signal to the process group (Ctrl-C) would otherwise stop the fork
    server in its imports, or the tracker (SIGHUP: a relaunched tracker then reports every
    queue it never saw), each with a traceback. They end when the processes they serve end."""
    if method == "fork" or os.name != "posix":  # Windows has no resource tracker
        return
    quiet_tracker()
    if method != "forkserver":
        return
    from multiprocessing import forkserver

    with signals_deferred():
        forkserver.ensure_running()  # the tracker runs: its check leaves the mask alone


def warm_up(modules: Iterable[str]) -> None:
    """Where workers start by `forkserver`, start the fork server now with the jobs'
    `modules` (`preload`: it imports them while the caller goes on), the resource tracker
    quietened first (`servers_for`)."""
    if not os.environ.get("PRINTGEN_SERIAL") and cores() > 1 and start_method() == "forkserver":
        preload(modules)


def quiet_tracker() -> None:
    """Start multiprocessing's resource tracker without its "leaked semaphore objects" warning.
    A run stopped at its time limit (or by a signal) kills the helper while its workers' queues
    are registered with the tracker, which unlinks them when it exits and says so on stderr: a
    second line after make's one. The tracker inherits the -W options of sys.warnoptions
    when it starts (at the helper's first queue); one already running is left as it is."""
    from multiprocessing import resource_tracker

    if TRACKER_WARNING not in sys.warnoptions:
        sys.warnoptions.append(TRACKER_WARNING)
    with signals_deferred():  # it ignores SIGINT and SIGTERM, and SIGHUP stays blocked
        resource_tracker.ensure_running()


def cores() -> int:
    """CPU cores this process may run on: its affinity (a container's or `taskset`'s share),
    else the machine's count."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def _one_thread() -> bool:
    """No Python thread runs here but the main one and the parent watch."""
    return all(t is threading.main_thread() or t.name == WATCH_THREAD
               for t in threading.enumerate())


@contextlib.contextmanager
def watch_is_safe() -> Iterator[None]:
    """Within the block, Python 3.12+'s warning that forking a process running threads may
    deadlock the child is not shown: `start_method` forks only beside the parent watch."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=r".*multi-threaded, use of fork\(\)",
                                category=DeprecationWarning)
        yield


# Why a start method runs the main script again in each worker (`start_method` picks them)
RERUNS = {"spawn": "how workers start on macOS and Windows",
          "forkserver": "how workers start on Linux from a process running threads, and on "
                        "other Unix systems"}
_GUARD = re.compile(r"""^\s*if\s+__name__\s*==\s*["']__main__["']\s*:""", re.MULTILINE)


def check_main_guard(method: str) -> None:
    """InputError before any worker starts when `method` starts workers by running the main
    script again (spawn, fork server: macOS and Windows, or a process with threads) and that
    script has its calls outside `if __name__ == "__main__":`: each worker would run them again
    and the pool would break, which used to read as a worker killed or out of memory. A
    notebook, the command line and `python -m` have no such script."""
    if method == "fork":
        return
    main = sys.modules.get("__main__")
    path = getattr(main, "__file__", None)
    spec = getattr(main, "__spec__", None)
    if not path or not str(path).endswith(".py") or (spec is not None
                                                      and spec.name.endswith("__main__")):
        return
    try:
        text = Path(path).read_text("utf-8", errors="replace")
    except OSError:
        return
    if not _GUARD.search(text):
        raise InputError(f"{path} runs printgen's parallel work, whose worker processes start "
                         f"by running this script again ({method}: {RERUNS.get(method, method)})"
                         ": put the script's calls under `if __name__ == \"__main__\":` (see "
                         "the Python API section of docs/user-guide.md), or set "
                         "PRINTGEN_SERIAL=1 to run in one process")
