"""The lock beside an output folder (`.NAME.lock`, holding the pid): one run per folder.

The lock file is opened without following symbolic links (O_NOFOLLOW) and must be a regular file
with no other name: a symbolic or hard link, a folder or a FIFO planted at its name is refused,
never written through (a hard link is a regular file to `fstat`; its link count tells). Two ways to
hold it, chosen by what the platform has:

- `flock`: where `fcntl` exists (Linux, macOS, BSD), an advisory lock on the open file; the
  kernel drops it when the process dies, so a SIGKILL leaves nothing to clean up.
- `exclusive`: elsewhere (Windows) or when forced, the file is created with O_CREAT | O_EXCL
  and holds the pid; a lock whose pid no longer runs (a killed run) is broken and taken.

The lock file is removed on release in both.
"""

from __future__ import annotations

import contextlib
import errno
import importlib
import importlib.util
import os
import secrets
import stat
from collections.abc import Iterator
from pathlib import Path

from printgen.outputs.files import OutputError, kind_of, named

NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)  # not on Windows: there a link is checked with lstat
PID_BYTES = 32  # a pid and a newline, with room to spare
BACKEND = "flock" if importlib.util.find_spec("fcntl") else "exclusive"


class LockError(OutputError):
    """The output folder's lock is held by another run, or its path is not a plain file."""


def lock_path(dest: Path) -> Path:
    """`.NAME.lock` beside `dest`."""
    return dest.parent / f".{dest.name}.lock"


@contextlib.contextmanager
def folder_lock(dest: Path, backend: str | None = None) -> Iterator[None]:
    """Hold the exclusive lock of `dest`; LockError naming the holder's pid when another run
    holds it, or when its path is a link or not a regular file."""
    how = backend or BACKEND
    if how not in ("flock", "exclusive"):
        raise ValueError(f"lock backend {how!r}: flock or exclusive")
    fd = (_flock if how == "flock" else _exclusive)(dest, lock_path(dest))
    try:
        try:
            os.ftruncate(fd, 0)
            os.write(fd, f"{os.getpid()}\n".encode())
        except OSError as exc:  # a full disk: write() names no file, the message must
            raise named(exc, lock_path(dest)) from None
        yield
    finally:
        if how == "exclusive":  # closed first: Windows cannot remove an open file
            os.close(fd)
        with contextlib.suppress(FileNotFoundError):
            os.unlink(lock_path(dest))  # flock: removed while held, so no one locks a ghost
        if how == "flock":
            os.close(fd)


def check_lock_path(dest: Path) -> None:
    """LockError now (before any work) when the lock path of `dest` is there and is not a
    regular file: a link, a folder or a FIFO planted at its name."""
    path = lock_path(dest)
    try:
        mode = os.lstat(path).st_mode
    except (FileNotFoundError, NotADirectoryError):
        return
    if stat.S_ISLNK(mode):
        raise _not_plain(path, "a symbolic link")
    if not stat.S_ISREG(mode):
        raise _not_plain(path, kind_of(mode))
    if os.lstat(path).st_nlink > 1:
        raise _not_plain(path, "a hard link to another file")


def _open(path: Path, flags: int) -> int:
    """Open the lock file without following a link; LockError unless it is a regular file."""
    if not NOFOLLOW and path.is_symlink():
        raise _not_plain(path, "a symbolic link")
    try:
        fd = os.open(path, flags | NOFOLLOW | getattr(os, "O_NONBLOCK", 0), 0o644)
    except OSError as exc:
        if exc.errno == errno.ELOOP or (exc.errno == errno.EMLINK and path.is_symlink()):
            raise _not_plain(path, "a symbolic link") from None
        if exc.errno == errno.EISDIR:
            raise _not_plain(path, "a folder") from None
        raise
    st = os.fstat(fd)
    if not stat.S_ISREG(st.st_mode):
        os.close(fd)
        raise _not_plain(path, "not a regular file")
    if st.st_nlink > 1:  # another name shares the file: writing the pid would change it
        os.close(fd)
        raise _not_plain(path, "a hard link to another file")
    return fd


def _not_plain(path: Path, what: str) -> LockError:
    return LockError(f"lock file {path} is {what}; printgen writes its pid there and will not "
                     "write through it: remove it (it is not printgen's) and run again")


def _busy(dest: Path, holder: str) -> LockError:
    return LockError(f"output {dest} is being written by another printgen "
                     f"(pid {holder or 'unknown'}); wait for it to finish or choose another --out")


def _holder(fd: int) -> str:
    return os.pread(fd, PID_BYTES, 0).decode("ascii", "replace").strip() if hasattr(
        os, "pread") else os.read(fd, PID_BYTES).decode("ascii", "replace").strip()


def _flock(dest: Path, path: Path) -> int:
    """Open (or create) the lock file and flock it; retry when the holder removed the file
    between our open and our lock (we would hold a lock on a name nobody sees)."""
    fcntl = importlib.import_module("fcntl")
    while True:
        fd = _open(path, os.O_RDWR | os.O_CREAT)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _holder(fd)
            os.close(fd)
            raise _busy(dest, holder) from None
        try:
            same = os.fstat(fd).st_ino == os.lstat(path).st_ino
        except FileNotFoundError:
            same = False
        if same:
            return fd
        os.close(fd)


def _exclusive(dest: Path, path: Path) -> int:
    """Create the lock file exclusively; break it once when the pid in it no longer runs."""
    for _ in range(3):
        try:
            return _open(path, os.O_RDWR | os.O_CREAT | os.O_EXCL)
        except FileExistsError:
            pass
        fd = _open(path, os.O_RDONLY)
        holder = _holder(fd)
        os.close(fd)
        if not holder.isdigit() or pid_alive(int(holder)):
            raise _busy(dest, holder)
        _break(path, holder)
    raise _busy(dest, "unknown")


def _break(path: Path, holder: str) -> None:
    """Move a stale lock aside and remove it; put it back if it was not the stale one (another
    run took the lock meanwhile)."""
    aside = path.with_name(f"{path.name}.stale.{secrets.token_hex(4)}")
    try:
        os.rename(path, aside)
    except FileNotFoundError:
        return
    fd = _open(aside, os.O_RDONLY)
    now = _holder(fd)
    os.close(fd)
    if now != holder and not path.exists():
        os.rename(aside, path)
        return
    os.unlink(aside)


def pid_alive(pid: int) -> bool:
    """Whether a process `pid` runs (a pid we may not signal runs too)."""
    if pid <= 0:
        return False
    if os.name == "nt":
        return _windows_pid_alive(pid)
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _windows_pid_alive(pid: int) -> bool:  # pragma: no cover - Windows only
    import ctypes

    kernel32 = ctypes.WinDLL("kernel32", use_last_error=True)
    handle = kernel32.OpenProcess(0x1000, False, pid)  # PROCESS_QUERY_LIMITED_INFORMATION
    if not handle:
        return ctypes.get_last_error() == 5  # ERROR_ACCESS_DENIED: it exists
    code = ctypes.c_ulong()
    try:
        ok = kernel32.GetExitCodeProcess(handle, ctypes.byref(code))
    finally:
        kernel32.CloseHandle(handle)
    return bool(ok) and code.value == 259  # STILL_ACTIVE
