"""Write outputs atomically: into a temporary sibling, then rename into place.

A failed step leaves neither partial files nor a damaged previous output.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path


def write_bytes(path: str | Path, data: bytes) -> Path:
    """Write `data` to `path` via a temp file in the same directory and `os.replace`."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=p.parent, prefix=f".{p.name}.", suffix=".tmp")
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


@contextlib.contextmanager
def staged_dir(final: str | Path) -> Iterator[Path]:
    """Yield an empty staging directory; on success move its files into `final`.

    On an exception the staging directory is removed and `final` is untouched. Files already
    in `final` with the same names are replaced one by one with `os.replace`.
    """
    dest = Path(final)
    dest.parent.mkdir(parents=True, exist_ok=True)
    stage = Path(tempfile.mkdtemp(dir=dest.parent, prefix=f".{dest.name}.stage."))
    try:
        yield stage
        dest.mkdir(exist_ok=True)
        for item in sorted(stage.rglob("*")):
            target = dest / item.relative_to(stage)
            if item.is_dir():
                target.mkdir(exist_ok=True)
            else:
                os.replace(item, target)
    finally:
        shutil.rmtree(stage, ignore_errors=True)
