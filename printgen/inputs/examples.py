"""The bundled examples: example prototypes (`realistic_barrier.toml` is the example
`realistic`), example folders of data files (the paper's printed design and its measured
test) and the notebook that walks the 1:40 barrier through the Python API (`notebook`), from
the package data or the checkout's examples/."""

from __future__ import annotations

import secrets
import shutil
from dataclasses import dataclass
from pathlib import Path

from printgen.errors import InputError
from printgen.inputs.profiles import bundled_dir
from printgen.outputs.files import write_bytes

SUFFIX = "_barrier"  # realistic_barrier.toml is the example `realistic`
NOTEBOOK = ("notebook", "realistic_1_40.ipynb")  # (its example name, its file)
DATA_SUFFIXES = {".json", ".csv", ".toml"}  # what an example folder holds


@dataclass(frozen=True)
class Example:
    """One bundled example: its name, where it is (a TOML file or a folder), and its files
    (copied into a new folder when asked: `example(name, out)`)."""

    name: str
    path: Path
    files: tuple[Path, ...]

    @property
    def is_folder(self) -> bool:
        """A folder of data files, not one prototype file."""
        return self.path.is_dir()

    @property
    def default_file(self) -> str | None:
        """The file `printgen example NAME` writes without FILE (the notebook's name), or
        None: the example is printed."""
        return NOTEBOOK[1] if self.name == NOTEBOOK[0] else None


def examples() -> dict[str, Path]:
    """Example name -> its TOML file or its folder of data files; InputError when none is
    installed."""
    root = bundled_dir("examples")
    files = sorted(root.glob("*.toml"))
    folders = sorted(d for d in root.glob("*") if d.is_dir() and example_files(d))
    found = {f.stem.removesuffix(SUFFIX): f for f in files} | {d.name: d for d in folders}
    if (root / NOTEBOOK[1]).is_file():
        found[NOTEBOOK[0]] = root / NOTEBOOK[1]
    if not found:
        raise InputError(f"no example prototypes in {root}; reinstall printgen")
    return found


def example_files(folder: Path) -> list[Path]:
    """The data files of an example folder (design files, measured tests)."""
    return sorted(f for f in folder.iterdir() if f.suffix in DATA_SUFFIXES and f.is_file())


def example(name: str, out: str | Path | None = None, *,
            file: str | Path | None = None) -> Example:
    """The example `name` (its file name, with or without .toml and `SUFFIX`, also names it);
    with `out`, its files copied into that new folder (`copy_example`); with `file`, a one-file
    example written into that new file (`write_example`). InputError naming the examples when
    there is none of that name, or for `out` and `file` both."""
    if out is not None and file is not None:  # before anything is copied
        raise InputError("give FILE or --out DIR, not both")
    found = examples()
    key = name.lower().removesuffix(".toml").removesuffix(SUFFIX)
    if key not in found:
        raise InputError(f"no example named {name!r}; examples: {', '.join(found)}")
    path = found[key]
    files = example_files(path) if path.is_dir() else [path]
    if out is not None:
        files = copy_example(path, Path(out))
    ex = Example(key, path, tuple(files))
    if file is not None:
        return Example(key, path, (write_example(ex, file),))
    return ex


def write_example(ex: Example, file: str | Path) -> Path:
    """The single-file example `ex` (a prototype, the notebook) written, byte for byte, into
    the new file `file`; InputError for a folder of files or a `file` that exists."""
    path = Path(file)
    if ex.is_folder:
        raise InputError(f"example {ex.name} is a folder of files; copy it with "
                         f"`printgen example {ex.name} --out DIR`")
    if path.exists() or path.is_symlink():
        raise InputError(f"{path} exists; name a new file")
    return write_bytes(path, ex.path.read_bytes())


def copy_example(src: Path, out: Path) -> list[Path]:
    """The example's files copied into the new folder `out` (written as a whole: a temporary
    folder renamed at the end), refused when `out` exists."""
    if out.exists() or out.is_symlink():
        raise InputError(f"--out {out} exists; name a new folder")
    files = example_files(src) if src.is_dir() else [src]
    out.parent.mkdir(parents=True, exist_ok=True)
    # a name of its own (mkdir refuses one that is there): a folder the user keeps beside
    # `out`, whatever its name, is never this stage and never removed
    stage = out.with_name(f".{out.name}.example-{secrets.token_hex(4)}.tmp")
    stage.mkdir()
    try:
        for f in files:
            write_bytes(stage / f.name, f.read_bytes())
        stage.rename(out)
    finally:
        if stage.exists():
            shutil.rmtree(stage, ignore_errors=True)
    return [out / f.name for f in files]
