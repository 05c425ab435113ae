"""A run's own temporary folder: where the libraries' temporary files go (multiprocessing's
`pymp-*` folder of the fork server and the workers' queues, a slicer's or Chromium's scratch
files through TMPDIR), so none is left in the system's temporary folder. A run killed with
SIGKILL cannot remove its folder: the next run removes every such folder whose process no
longer runs."""

from __future__ import annotations

import atexit
import os
import re
import shutil
import tempfile
from pathlib import Path

from printgen.outputs.lock import pid_alive

PREFIX = "printgen-run-"  # printgen-run-<pid>-<random>: the pid tells a stale folder
# A Unix socket's path holds at most 107 bytes (Linux; 103 on macOS): multiprocessing's fork
# server listens at <tmp>/pymp-XXXXXXXX/listener-XXXXXXXX, so a long TMPDIR is left as it is.
SOCKET_PATH_MAX = 103
OWN_NAME_CHARS = len(PREFIX) + 7 + 1 + 8 + 1  # "printgen-run-<pid>-<8 random>/"
SOCKET_TAIL_CHARS = len("pymp-XXXXXXXX/listener-XXXXXXXX")
_NAME = re.compile(rf"^{re.escape(PREFIX)}(\d+)-[^/]+$")


def private_tempdir(base: str | Path | None = None) -> Path | None:
    """Make this process's temporary folder under `base` (default: the system's), point
    `tempfile` and TMPDIR (inherited by workers and subprocesses) at it, remove it at exit,
    and remove the folders of runs that no longer run; returns it. None (nothing changed)
    when `base` is so long that the fork server's socket path beneath it would pass the
    operating system's limit (SOCKET_PATH_MAX)."""
    root = Path(base or tempfile.gettempdir())
    remove_stale(root)
    if len(str(root)) + OWN_NAME_CHARS + SOCKET_TAIL_CHARS > SOCKET_PATH_MAX:
        return None
    mine = Path(tempfile.mkdtemp(prefix=f"{PREFIX}{os.getpid()}-", dir=root))
    tempfile.tempdir = str(mine)
    os.environ["TMPDIR"] = str(mine)
    atexit.register(shutil.rmtree, mine, ignore_errors=True)
    return mine


def remove_stale(root: Path) -> list[Path]:
    """Remove the run folders under `root` whose process no longer runs (killed runs')."""
    gone: list[Path] = []
    try:
        entries = list(os.scandir(root))
    except OSError:
        return gone
    for e in entries:
        m = _NAME.match(e.name)
        if m and e.is_dir(follow_symlinks=False) and not pid_alive(int(m.group(1))):
            shutil.rmtree(e.path, ignore_errors=True)
            gone.append(Path(e.path))
    return gone
