"""Single files: written atomically (temp file + rename), read only when regular and small.

Every input printgen reads (prototype and profile TOML, design.json, measured CSV, tensile
exports, a folder's manifest) goes through `read_input`: a FIFO, a device (/dev/zero), a socket
or a folder is refused with a message saying what it is, and a file larger than its limit is
refused before it is read, so no input can hang a run or fill the memory.
"""

from __future__ import annotations

import codecs
import contextlib
import errno
import os
import secrets
import stat
from pathlib import Path

from printgen.errors import InputError

# Default cap of one input file: the largest real input (a tensile export of ~10^5 rows) is a
# few MB; 64 MiB leaves room for long exports and refuses /dev/zero-like streams early.
INPUT_LIMIT_BYTES = 64 << 20
# OS errors caused by the path the user gave (exit 2); the rest are the machine's (exit 1).
INPUT_ERRNOS = {errno.ENOENT, errno.ENOTDIR, errno.EISDIR, errno.EEXIST, errno.EACCES,
                errno.EPERM, errno.EROFS, errno.ENAMETOOLONG, errno.ELOOP, errno.EXDEV,
                errno.ENOTEMPTY, errno.EBUSY}
FULL_ERRNOS = {errno.ENOSPC, getattr(errno, "EDQUOT", errno.ENOSPC)}  # disk or quota full


class OutputError(InputError):
    """The output path cannot be used as given (a file, a foreign folder, busy)."""


class InputFileError(InputError):
    """An input path is missing, not a regular file, or too large."""


def kind_of(mode: int) -> str:
    """'a folder', 'a FIFO (named pipe)', ... for the st_mode of something that is not a file."""
    for test, name in ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
                       (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return name
    return "not a regular file"


def read_input(path: str | Path, what: str = "input file", *,
               limit: int = INPUT_LIMIT_BYTES) -> bytes:
    """The bytes of the regular file `path` (symbolic links followed), at most `limit` bytes.

    Opened without blocking (a FIFO does not wait for a writer), then checked with fstat, so
    what is read is what was checked. InputFileError names the path, what it is and the limit.
    """
    p = Path(path)
    try:
        fd = os.open(p, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0))
    except FileNotFoundError:
        raise InputFileError(f"file not found: {p} ({what}); check the path (relative to "
                             f"{Path.cwd()})") from None
    except IsADirectoryError:
        raise InputFileError(f"{what} {p} is a folder, not a file; name the file itself") from None
    except OSError as exc:
        raise InputFileError(f"cannot read {what} {p}: {exc.strerror}") from None
    st = os.fstat(fd)
    if not stat.S_ISREG(st.st_mode):
        os.close(fd)
        raise InputFileError(f"{what} {p} is {kind_of(st.st_mode)}, not a regular file; "
                             "give a file saved on disk")
    if st.st_size > limit:
        os.close(fd)
        raise InputFileError(f"{what} {p} is {st.st_size:,} bytes, over the {limit:,}-byte "
                             "limit for this input; is it the right file?")
    with os.fdopen(fd, "rb") as fh:
        if hasattr(os, "set_blocking"):  # opened O_NONBLOCK so a FIFO cannot hang the open
            with contextlib.suppress(OSError):  # Windows: not for every kind of file
                os.set_blocking(fd, True)
        data = fh.read(limit + 1)
    if len(data) > limit:  # grew while being read
        raise InputFileError(f"{what} {p} holds more than {limit:,} bytes; is it the right file?")
    return data


def read_input_text(path: str | Path, what: str = "input file", *,
                    limit: int = INPUT_LIMIT_BYTES, encoding: str = "utf-8") -> str:
    """`read_input` decoded; InputFileError when it is not text in `encoding`."""
    data = read_input(path, what, limit=limit)
    if encoding.replace("-", "").lower() == "utf8" and data.startswith(codecs.BOM_UTF8):
        data = data[len(codecs.BOM_UTF8):]  # Windows editors mark UTF-8 so; TOML/JSON may not
    try:
        return data.decode(encoding)
    except UnicodeDecodeError as exc:
        raise InputFileError(f"{what} {path} is not {encoding} text ({exc.reason} at byte "
                             f"{exc.start}); save it as {encoding}") from None


def write_bytes(path: str | Path, data: bytes) -> Path:
    """Write `data` to `path` via a temp file in the same directory and `os.replace`."""
    p = Path(path)
    created: list[Path] = []
    try:
        make_parents(p.parent, created)
        return _write_new(p, data)
    except BaseException:
        for folder in reversed(created):  # a failed write leaves no empty folders behind
            with contextlib.suppress(OSError):
                os.rmdir(folder)
        raise


def make_parents(folder: Path, created: list[Path]) -> None:
    """Create `folder` and its missing parents, appending each one created to `created`
    (outermost first) as it is made."""
    missing = []
    here = Path(folder)
    while not os.path.lexists(here) and here != here.parent:
        missing.append(here)
        here = here.parent
    for f in reversed(missing):
        try:
            f.mkdir()
        except FileExistsError:  # made meanwhile by someone else: theirs, not ours to remove
            continue
        created.append(f)


def _write_new(p: Path, data: bytes) -> Path:
    """Write `data` to a temp file beside `p`, then rename it to `p`."""
    tmp = p.parent / f".{p.name}.{secrets.token_hex(4)}.tmp"
    # 0o666 less the umask, as any file the user writes (mkstemp would force 0600)
    # O_EXCL refuses any name already there, a link too; O_NOFOLLOW (absent on Windows) also
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0), 0o666)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.replace(tmp, p)
    except OSError as exc:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise named(exc, p) from None
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise
    return p


def write_text(path: str | Path, text: str) -> Path:
    """Text version of `write_bytes` (UTF-8, newlines as given)."""
    return write_bytes(path, text.encode("utf-8"))


def named(exc: OSError, path: str | Path) -> OSError:
    """`exc` with `path` as its file name when it has none (a failed write() names no file)."""
    if exc.filename is not None:
        return exc
    return type(exc)(exc.errno, exc.strerror or str(exc), str(path))


def os_error_exit_code(exc: OSError) -> int:
    """2 when the path given is at fault (missing, a file, read-only, no permission), else 1."""
    return 2 if exc.errno in INPUT_ERRNOS else 1


def describe_os_error(exc: OSError) -> str:
    """One line: the path(s), the OS's reason, and for a full disk what to do."""
    where = " -> ".join(str(p) for p in (exc.filename, exc.filename2) if p is not None)
    reason = exc.strerror or str(exc)
    if exc.errno in FULL_ERRNOS:
        reason += ("; free space on that file system (or choose --out on another), then run "
                   "again: nothing was replaced")
    return f"{where}: {reason}" if where else reason
