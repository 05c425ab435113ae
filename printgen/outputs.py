"""The output folder: files written atomically, and whole runs swapped in as one folder.

A `make` run is built in a sibling stage folder (`.OUT.stage.XXXX`) and swapped in as a whole
when every step succeeded: on Linux with `renameat2(RENAME_EXCHANGE)` (one atomic step), else by
renaming the old folder aside, the stage in, and removing the old one. At every instant the
output path holds one complete run or the previous one, never a mix, and nothing of an earlier
run survives a new one. An exclusive lock beside the output (`.OUT.lock`, holding the pid)
keeps a second run out of the same folder; stale stages of the same output (a run killed with
SIGKILL) are removed when the next run starts. Each folder carries `manifest.json`: every
file's sha256 and size, plus what the caller adds (version, inputs, command line), and the
`volatile` files whose bytes may differ between identical runs (timings).
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import fcntl
import hashlib
import json
import os
import secrets
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from printgen.errors import InputError

MANIFEST = "manifest.json"
MANIFEST_FORMAT = 1
RENAME_EXCHANGE = 2  # linux/fs.h: atomically exchange two paths
AT_FDCWD = -100  # linux/fcntl.h: paths relative to the current directory
CHUNK_BYTES = 1 << 20  # read size when hashing files
# OS errors caused by the path the user gave (exit 2); the rest are the machine's (exit 1).
INPUT_ERRNOS = {errno.ENOENT, errno.ENOTDIR, errno.EISDIR, errno.EEXIST, errno.EACCES,
                errno.EPERM, errno.EROFS, errno.ENAMETOOLONG, errno.ELOOP, errno.EXDEV}


class OutputError(InputError):
    """The output path cannot be used as given (a file, a foreign folder, busy)."""


def write_bytes(path: str | Path, data: bytes) -> Path:
    """Write `data` to `path` via a temp file in the same directory and `os.replace`."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    tmp = p.parent / f".{p.name}.{secrets.token_hex(4)}.tmp"
    # 0o666 less the umask, as any file the user writes (mkstemp would force 0600)
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o666)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.replace(tmp, p)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise
    return p


def write_text(path: str | Path, text: str) -> Path:
    """Text version of `write_bytes` (UTF-8, newlines as given)."""
    return write_bytes(path, text.encode("utf-8"))


def os_error_exit_code(exc: OSError) -> int:
    """2 when the path given is at fault (missing, a file, read-only, no permission), else 1."""
    return 2 if exc.errno in INPUT_ERRNOS else 1


def describe_os_error(exc: OSError) -> str:
    """One line: the path(s) and the OS's reason."""
    where = " -> ".join(str(p) for p in (exc.filename, exc.filename2) if p is not None)
    reason = exc.strerror or str(exc)
    return f"{where}: {reason}" if where else reason


@contextlib.contextmanager
def staged_dir(final: str | Path, *, force: bool = False,
               meta: dict[str, Any] | None = None,
               volatile: tuple[str, ...] = ()) -> Iterator[Path]:
    """Yield an empty stage folder; on success swap it in as the whole of `final`.

    final : the output folder. It must be absent, empty, or an earlier printgen output (it holds
    `manifest.json`); anything else needs `force`. meta : added to the manifest (the caller may
    fill it while the stage is being written). volatile : names of files whose bytes may differ
    between identical runs (at most one: the timings).
    On an exception (or a signal turned into one) the stage is removed and `final` untouched.
    """
    dest = Path(os.path.abspath(final))  # "." and "a/.." have a name and a parent this way
    check_destination(dest, force=force)
    make_parent(dest)
    with folder_lock(dest):
        remove_stale(dest)
        stage = dest.parent / f".{dest.name}.stage.{secrets.token_hex(4)}"
        stage.mkdir()  # (not mkdtemp: the folder keeps the user's umask, not 0700)
        try:
            yield stage
            write_manifest(stage, meta or {}, volatile)
            swap_in(stage, dest)
        finally:
            shutil.rmtree(stage, ignore_errors=True)


def check_destination(dest: Path, *, force: bool) -> None:
    """Raise OutputError unless `dest` may be replaced by a new run."""
    if dest.is_symlink():
        raise OutputError(f"output {dest} is a symbolic link (to {os.readlink(dest)}); a run "
                          "replaces its folder whole, so give --out the folder itself")
    if dest.exists() and not dest.is_dir():
        raise OutputError(f"output {dest} exists and is not a folder; give --out a new or "
                          "empty folder, or an earlier printgen output")
    if dest.is_dir() and not force and not (dest / MANIFEST).is_file() and any(dest.iterdir()):
        raise OutputError(f"output {dest} holds files printgen did not write (no {MANIFEST}); "
                          "choose a new or empty folder, or pass --force to replace it whole")
    for parent in dest.parents:
        if parent.exists():
            if not parent.is_dir():
                raise OutputError(f"cannot create output {dest}: {parent} is a file; give "
                                  "--out a path in a folder")
            break


def make_parent(dest: Path) -> None:
    """Create the folder that will hold `dest` (OS errors propagate as one-line OSError)."""
    dest.parent.mkdir(parents=True, exist_ok=True)


@contextlib.contextmanager
def folder_lock(dest: Path) -> Iterator[None]:
    """Hold an exclusive lock on `.NAME.lock` beside `dest`; raise OutputError naming the pid
    of the process that holds it. The lock file is removed on release."""
    path = dest.parent / f".{dest.name}.lock"
    while True:
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 32, 0).decode("ascii", "replace").strip() or "unknown"
            os.close(fd)
            raise OutputError(f"output {dest} is being written by another printgen (pid "
                              f"{holder}); wait for it to finish or choose another --out") from None
        try:
            same = os.fstat(fd).st_ino == os.stat(path).st_ino
        except FileNotFoundError:  # the holder removed it between our open and our lock
            same = False
        if same:
            break
        os.close(fd)
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        yield
    finally:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(path)
        os.close(fd)


def remove_stale(dest: Path) -> list[Path]:
    """Remove stage and aside folders of `dest` left by killed runs (call under the lock)."""
    stale = [p for pattern in (f".{dest.name}.stage.*", f".{dest.name}.old.*")
             for p in dest.parent.glob(pattern) if p.is_dir() and not p.is_symlink()]
    for p in stale:
        shutil.rmtree(p, ignore_errors=True)
    return stale


def swap_in(stage: Path, dest: Path) -> None:
    """Make `stage` the folder `dest`: exchange atomically when the OS can, else rename the
    old folder aside first. `stage` ends up holding the previous run (or nothing)."""
    if not dest.exists():
        os.rename(stage, dest)
        return
    if exchange(stage, dest):
        return
    aside = dest.parent / f".{dest.name}.old.{os.getpid()}"
    os.rename(dest, aside)
    try:
        os.rename(stage, dest)
    except BaseException:
        os.rename(aside, dest)
        raise
    shutil.rmtree(aside, ignore_errors=True)


def exchange(a: Path, b: Path) -> bool:
    """Swap two paths atomically with renameat2(RENAME_EXCHANGE); False when the OS or file
    system cannot (then the caller falls back to rename-aside). Other OS errors raise."""
    try:
        fn = ctypes.CDLL(None, use_errno=True).renameat2
    except (AttributeError, OSError):
        return False
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    if fn(AT_FDCWD, os.fsencode(a), AT_FDCWD, os.fsencode(b), RENAME_EXCHANGE) == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.ENOSYS, errno.EINVAL, errno.ENOTSUP):
        return False
    raise OSError(err, os.strerror(err), str(a), None, str(b))


def file_digest(path: Path) -> dict[str, Any]:
    """{"sha256": hex, "bytes": size} of one file."""
    h, size = hashlib.sha256(), 0
    with open(path, "rb") as fh:
        while chunk := fh.read(CHUNK_BYTES):
            h.update(chunk)
            size += len(chunk)
    return {"sha256": h.hexdigest(), "bytes": size}


def folder_files(folder: Path) -> list[str]:
    """Relative POSIX paths of every file under `folder`, sorted."""
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file())


def write_manifest(folder: Path, meta: dict[str, Any], volatile: tuple[str, ...]) -> dict:
    """Write `manifest.json`: meta, the volatile names, and every other file's digest.

    Volatile files are listed by name only, so that identical runs give identical manifests.
    """
    if len(volatile) > 1:
        raise ValueError(f"at most one volatile file (the timings), got {volatile}")
    files = {rel: file_digest(folder / rel) for rel in folder_files(folder)
             if rel != MANIFEST and rel not in volatile}
    manifest = {**meta, "format": MANIFEST_FORMAT, "files": files, "volatile": list(volatile)}
    text = json.dumps(manifest, indent=2, sort_keys=True) + "\n"
    (folder / MANIFEST).write_text(text, encoding="utf-8")
    return manifest


def read_manifest(folder: Path) -> dict[str, Any]:
    """The manifest of an output folder; InputError when the folder or manifest is missing."""
    path = Path(folder) / MANIFEST
    if not Path(folder).is_dir():
        raise InputError(f"{folder} is not a folder; give a printgen output folder")
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(f"{folder} has no {MANIFEST}: it is not a printgen output folder "
                         "(or was written before manifests existed); run make again") from None
    except (ValueError, UnicodeDecodeError, RecursionError) as exc:  # JSON, digits, nesting
        raise InputError(f"{path} is not valid JSON ({type(exc).__name__}: "
                         f"{' '.join(str(exc).split())[:120]}); the folder was altered") from None
    if not isinstance(data, dict) or not isinstance(data.get("files"), dict):
        raise InputError(f"{path} has no 'files' table; the folder was altered")
    check_manifest_shape(data, path)
    return data


def check_manifest_shape(data: dict[str, Any], path: Path) -> None:
    """InputError unless every entry has the type `write_manifest` gives it: files maps a
    name to {"sha256": text, "bytes": whole number}; volatile and command are lists of text."""
    def bad(what: str) -> InputError:
        return InputError(f"{path}: {what}; the folder was altered (run make again)")

    for name, entry in data["files"].items():
        if not (isinstance(entry, dict) and isinstance(entry.get("sha256"), str)
                and type(entry.get("bytes")) is int):
            raise bad(f"files entry {name[:80]!r} is not {{\"sha256\": ..., \"bytes\": ...}}")
    for key in ("volatile", "command"):
        value = data.get(key, [])
        if value is not None and not (isinstance(value, list)
                                      and all(isinstance(v, str) for v in value)):
            raise bad(f"{key!r} is not a list of text")
    if not isinstance(data.get("printgen_version", ""), str):
        raise bad("'printgen_version' is not text")


def check_folder(folder: Path) -> list[str]:
    """What differs between `folder` and its manifest: one line per file, [] when it matches."""
    folder = Path(folder)
    m = read_manifest(folder)
    volatile = set(m.get("volatile", []))
    present = set(folder_files(folder)) - {MANIFEST}
    out = []
    for rel, want in sorted(m["files"].items()):
        if rel not in present:
            out.append(f"missing: {rel}")
            continue
        got = file_digest(folder / rel)
        if got != want:
            out.append(f"changed: {rel} ({got['bytes']} bytes, sha256 {got['sha256'][:12]}; "
                       f"manifest: {want.get('bytes')} bytes, {str(want.get('sha256'))[:12]})")
    out += [f"missing: {rel} (volatile)" for rel in sorted(volatile - present)]
    out += [f"extra: {rel}" for rel in sorted(present - set(m["files"]) - volatile)]
    return out
