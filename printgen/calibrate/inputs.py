"""Which files to calibrate: the exports named, and every export in a directory named.

Extensions are matched without regard to case (`.csv`, `.CSV`, `.Txt`, `.csv.zip`); sidecar
`.toml` files (specimen sizes, columns) are never read as data, even when a glob catches them;
the compliance-curve file is left out too.
"""

from __future__ import annotations

import logging
from collections.abc import Iterable, Sequence
from pathlib import Path

from printgen.calibrate.reader import TEXT_SUFFIXES
from printgen.errors import CalibrationError
from printgen.outputs.files import kind_of

log = logging.getLogger(__name__)

DATA_SUFFIXES = (*TEXT_SUFFIXES, ".zip")
SIDECAR_SUFFIX = ".toml"


def is_export(path: Path) -> bool:
    """True for a file whose extension (any case) is one of DATA_SUFFIXES."""
    return path.suffix.lower() in DATA_SUFFIXES


def expand(paths: Sequence[str | Path], *, exclude: Iterable[str | Path] = ()
           ) -> tuple[list[tuple[Path, bool]], list[str]]:
    """([(export, found in a directory)], notes): directories give every export in them,
    sorted; sidecars and `exclude` are skipped with a note. A missing path is an error."""
    skip = {Path(p).resolve() for p in exclude}
    out: list[tuple[Path, bool]] = []
    notes: list[str] = []
    for raw in paths:
        p = Path(raw)
        if p.is_dir():
            found = sorted((f for f in p.iterdir() if f.is_file() and is_export(f)),
                           key=lambda f: f.name.lower())
            if not found:
                raise CalibrationError(
                    f"{p}: directory holds no exports ({', '.join(DATA_SUFFIXES)}, any case); "
                    "name the files, or put the exports in it")
            out += [(f, True) for f in found]
        elif p.is_file():
            if p.suffix.lower() == SIDECAR_SUFFIX:
                notes.append(f"{p.name}: a sidecar (.toml), not read as data")
                continue
            out.append((p, False))
        elif p.exists():
            raise CalibrationError(f"{p}: is {kind_of(p.stat().st_mode)}, not a regular file; "
                                   "give an export saved on disk")
        else:
            raise CalibrationError(f"{p}: file not found; check the path")
    kept = [(f, d) for f, d in out if f.resolve() not in skip]
    if len(kept) < len(out):
        notes.append("the compliance curve is not a specimen: left out of the exports")
    seen: set[Path] = set()
    unique = []
    for f, d in kept:
        if f.resolve() not in seen:
            seen.add(f.resolve())
            unique.append((f, d))
    if not unique:
        raise CalibrationError(f"no tensile-test exports among {', '.join(map(str, paths))}; "
                               f"expected files ending in {', '.join(DATA_SUFFIXES)}")
    return unique, notes
