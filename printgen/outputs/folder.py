"""The output folder: whole runs swapped in as one folder, and nothing outside it touched.

A run is built in a sibling stage folder (`.OUT.stage.XXXXXXXX`) and swapped in as a whole
when every step succeeded: on Linux with `renameat2(RENAME_EXCHANGE)` (one atomic step), else by
renaming the old folder aside (`.OUT.old.XXXXXXXX`), the stage in, and removing the old one. At
every instant the output path holds one complete run or the previous one, never a mix; if a
run is killed between the fallback's two renames, the next run to start puts the old folder
back before anything else, and no run removes an old folder before its own is in place.

What may be replaced: an absent or empty folder, or a printgen output (its manifest reads, and the
folder holds exactly the files it lists, each as the run wrote it: `manifest.foreign_entry`,
`manifest.edited_files`); anything else needs `force`. Never replaced: a symbolic link, a mount
point, a folder holding one of the run's inputs. An exclusive lock beside the output
(`lock.folder_lock`) keeps a second run out of the same folder; stale stages of the same output (a
run killed with SIGKILL) are removed when the next run starts. Stage, aside and lock names are
matched literally (an output named `*` is the folder `*`, not a pattern).
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import logging
import os
import re
import secrets
import shutil
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

from printgen.executor.signals import raise_received, signals_deferred
from printgen.outputs.files import FULL_ERRNOS, OutputError, named
from printgen.outputs.lock import check_lock_path, folder_lock
from printgen.outputs.manifest import edited_files, foreign_entry, write_manifest

log = logging.getLogger(__name__)

RENAME_EXCHANGE = 2  # linux/fs.h: atomically exchange two paths
AT_FDCWD = -100  # linux/fcntl.h: paths relative to the current directory
TOKEN_BYTES = 4  # random hex in stage and aside names
_trackers: list[list[Path]] = []  # `tracking_swaps` lists: outputs replaced meanwhile


@contextlib.contextmanager
def staged_dir(final: str | Path, *, force: bool = False,
               meta: dict[str, Any] | None = None, volatile: tuple[str, ...] = (),
               inputs: Iterable[str | Path] = ()) -> Iterator[Path]:
    """Yield an empty stage folder; on success swap it in as the whole of `final`.

    final : the output folder (see the module docstring for what may be replaced; `force`
    allows a folder printgen did not write). meta : added to the manifest (the caller may fill
    it while the stage is being written). volatile : the timings file, whose bytes differ
    between identical runs. inputs : the run's input files and folders, none of which may lie
    inside `final`. On an exception (or a signal turned into one) the stage is removed and
    `final` untouched.
    """
    dest = Path(os.path.abspath(final))  # "." and "a/.." have a name and a parent this way
    inputs = list(inputs)
    check_destination(dest, force=force, inputs=inputs)
    make_parent(dest)
    with folder_lock(dest):
        restore_orphan(dest)
        remove_stale(dest)
        check_destination(dest, force=force, inputs=inputs)  # as it is now, under the lock
        stage = dest.parent / f".{dest.name}.stage.{secrets.token_hex(TOKEN_BYTES)}"
        stage.mkdir()  # (not mkdtemp: the folder keeps the user's umask, not 0700)
        try:
            try:
                yield stage
                write_manifest(stage, meta or {}, volatile)
            except OSError as exc:  # a full disk fails in write(), which names no file
                raise (named(exc, stage) if exc.errno in FULL_ERRNOS else exc) from None
            raise_received()  # a signal a library swallowed: the run stops, its stage goes
            with signals_deferred():  # a signal now comes after the swap and its cleanup
                check_destination(dest, force=force, inputs=inputs)
                swap_in(stage, dest)
                for done in _trackers:
                    done.append(dest)
                remove_tree(stage, "the previous run")
                remove_stale(dest, "old")  # earlier runs' asides: the new run is in now
        finally:
            if os.path.lexists(stage):
                remove_tree(stage, "this run's unfinished stage")


def write_folder(final: str | Path, files: dict[str, str | bytes], *, force: bool = False,
                 volatile: tuple[str, ...] = (), inputs: Iterable[str | Path] = (),
                 meta: dict[str, Any] | None = None) -> list[str]:
    """Write `files` (relative path -> text or bytes; sub-folders made) as the whole of
    `final` through `staged_dir` (`meta` added to its manifest); returns the relative paths,
    sorted."""
    with staged_dir(final, force=force, volatile=volatile, inputs=inputs, meta=meta) as stage:
        for name, data in files.items():
            path = stage / name
            path.parent.mkdir(parents=True, exist_ok=True)
            if isinstance(data, bytes):
                path.write_bytes(data)
            else:
                path.write_text(data)
    return sorted(files)


@contextlib.contextmanager
def tracking_swaps() -> Iterator[list[Path]]:
    """Within the block, every output folder a run swaps in is appended to the list yielded
    (the command line says so when a signal stops it after its swap)."""
    done: list[Path] = []
    _trackers.append(done)
    try:
        yield done
    finally:
        _trackers.remove(done)


def check_destination(dest: Path, *, force: bool, inputs: Iterable[str | Path] = ()) -> None:
    """Raise OutputError unless `dest` may be replaced by a new run."""
    dest = Path(os.path.abspath(dest))
    if dest.is_symlink():
        raise OutputError(f"output {dest} is a symbolic link (to {os.readlink(dest)}); a run "
                          "replaces its folder whole, so give --out the folder itself")
    if dest.exists() and not dest.is_dir():
        raise OutputError(f"output {dest} exists and is not a folder; give --out a new or "
                          "empty folder, or an earlier printgen output")
    if dest.is_dir() and os.path.ismount(dest):
        raise OutputError(f"output {dest} is a mount point: a run replaces its folder whole by "
                          "renaming, which a mount point cannot be; give --out a folder inside "
                          f"it, e.g. {dest / 'printgen-out'}")
    check_inputs_outside(dest, inputs)
    if dest.is_dir() and not force:
        foreign = foreign_entry(dest)
        if foreign is not None:
            raise OutputError(f"output {dest} is not a printgen output folder: it holds "
                              f"{foreign}; choose a new or empty folder, or pass --force to "
                              "replace it whole")
        edited = edited_files(dest)
        if edited:  # a lab's own readings: a new run replaces the folder whole
            raise OutputError(f"output {dest} holds {', '.join(edited)}, edited since printgen "
                              "wrote it (a lab's readings?); a new run would replace it: copy "
                              "it out of the folder first (or choose another --out), or pass "
                              "--force to replace the folder whole")
    for parent in dest.parents:
        if parent.exists():
            if not parent.is_dir():
                raise OutputError(f"cannot create output {dest}: {parent} is a file; give "
                                  "--out a path in a folder")
            break
    check_lock_path(dest)


def check_inputs_outside(dest: Path, inputs: Iterable[str | Path]) -> None:
    """OutputError when an input of the run lies inside `dest` (the run would remove it)."""
    real = os.path.realpath(dest)
    for item in inputs:
        if item is None:
            continue
        path = os.path.realpath(item)
        with contextlib.suppress(ValueError):  # other drive (Windows): not inside
            if os.path.commonpath([real, path]) == real:
                raise OutputError(f"input {item} is inside the output folder {dest}, which a run "
                                  "replaces whole (the input would be deleted); move the input "
                                  "out or choose another --out")


def make_parent(dest: Path) -> None:
    """Create the folder that will hold `dest` (OS errors propagate as one-line OSError)."""
    dest.parent.mkdir(parents=True, exist_ok=True)


def _siblings(dest: Path, kind: str) -> list[Path]:
    """The `.NAME.<kind>.<hex>` folders beside `dest` (names matched literally, links not
    followed), oldest first."""
    pattern = re.compile(re.escape(f".{dest.name}.{kind}.") + "[0-9a-f]+")
    found = []
    with os.scandir(dest.parent) as it:
        for e in it:
            if pattern.fullmatch(e.name) and e.is_dir(follow_symlinks=False):
                found.append((e.stat(follow_symlinks=False).st_mtime, Path(e.path)))
    return [p for _, p in sorted(found)]


def restore_orphan(dest: Path) -> Path | None:
    """When `dest` is missing but an aside folder of it is there (a run killed between the
    fallback's two renames), rename the newest one back to `dest` (call under the lock)."""
    if os.path.lexists(dest):
        return None
    olds = _siblings(dest, "old")
    if not olds:
        return None
    os.rename(olds[-1], dest)
    log.warning("restored the previous run into %s from %s (a run was stopped while swapping "
                "its folder in)", dest, olds[-1].name)
    return olds[-1]


def remove_stale(dest: Path, kind: str = "stage") -> list[Path]:
    """Remove the stage folders of `dest` left by killed runs (call under the lock, after
    `restore_orphan`), or with kind "old" its aside folders (only once a new run is in)."""
    stale = _siblings(dest, kind)
    for p in stale:
        remove_tree(p, "a stopped run's stage" if kind == "stage" else "an earlier run")
    return stale


def remove_tree(path: Path, what: str) -> bool:
    """Remove the folder `path` (`what` it holds, for the message); True when it is gone. A
    file that cannot be removed (immutable, another user's) leaves the folder beside the
    output: a warning names it and the reason, never silence (the new run is in either way)."""
    errors: list[str] = []
    shutil.rmtree(path, onerror=lambda _fn, p, exc: errors.append(f"{p}: {exc[1]}"))
    if not os.path.lexists(path):
        return True
    log.warning("could not remove %s in %s (%s); remove it by hand", what, path,
                errors[0] if errors else "unknown reason")
    return False


def swap_in(stage: Path, dest: Path) -> None:
    """Make `stage` the folder `dest`: exchange atomically when the OS can, else rename the
    old folder aside first. `stage` ends up holding the previous run (or nothing)."""
    if not os.path.lexists(dest):
        os.rename(stage, dest)
        return
    if exchange(stage, dest):
        return
    aside = dest.parent / f".{dest.name}.old.{secrets.token_hex(TOKEN_BYTES)}"
    os.rename(dest, aside)
    try:
        os.rename(stage, dest)
    except BaseException:
        os.rename(aside, dest)
        raise
    remove_tree(aside, "the previous run")


def exchange(a: Path, b: Path) -> bool:
    """Swap two paths atomically with renameat2(RENAME_EXCHANGE); False when the OS or file
    system cannot (then the caller falls back to rename-aside). Other OS errors raise."""
    try:
        fn = ctypes.CDLL(None, use_errno=True).renameat2
    except (AttributeError, OSError, TypeError):
        return False
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    if fn(AT_FDCWD, os.fsencode(a), AT_FDCWD, os.fsencode(b), RENAME_EXCHANGE) == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.ENOSYS, errno.EINVAL, errno.ENOTSUP):
        return False
    raise OSError(err, os.strerror(err), str(a), None, str(b))
