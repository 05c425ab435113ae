"""`printgen example [NAME] [--out DIR]`: print a bundled example prototype, e.g.
`printgen example realistic > proto.toml`, or copy a bundled example folder (the paper's printed
design and its measured test: `printgen example paper_1_40 --out paper`); without NAME, list
them."""

from __future__ import annotations

import argparse
import shutil
import sys
from pathlib import Path

from printgen.errors import InputError
from printgen.inputs.profiles import bundled_dir
from printgen.outputs.files import write_bytes

SUFFIX = "_barrier"  # realistic_barrier.toml is the example `realistic`
DATA_SUFFIXES = {".json", ".csv", ".toml"}  # what an example folder holds


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("example", help="print a bundled example prototype (TOML) to stdout")
    p.add_argument("name", nargs="?", help="which example (none: list them)")
    p.add_argument("--out", "-o", type=Path, metavar="DIR",
                   help="copy the example's files into DIR (a new folder) instead of printing")
    p.set_defaults(func=run)


def examples() -> dict[str, Path]:
    """Example name -> its TOML file or its folder of data files, from the package data (or
    the checkout's examples/)."""
    root = bundled_dir("examples")
    files = sorted(root.glob("*.toml"))
    folders = sorted(d for d in root.glob("*") if d.is_dir() and example_files(d))
    return {f.stem.removesuffix(SUFFIX): f for f in files} | {d.name: d for d in folders}


def example_files(folder: Path) -> list[Path]:
    """The data files of an example folder (design files, measured tests)."""
    return sorted(f for f in folder.iterdir() if f.suffix in DATA_SUFFIXES and f.is_file())


def copy_example(src: Path, out: Path) -> list[Path]:
    """The example's files copied into the new folder `out` (written as a whole: a temporary
    folder renamed at the end), refused when `out` exists."""
    if out.exists() or out.is_symlink():
        raise InputError(f"--out {out} exists; name a new folder")
    files = example_files(src) if src.is_dir() else [src]
    stage = out.with_name(f".{out.name}.example-tmp")
    shutil.rmtree(stage, ignore_errors=True)
    stage.mkdir(parents=True)
    try:
        for f in files:
            write_bytes(stage / f.name, f.read_bytes())
        stage.rename(out)
    finally:
        shutil.rmtree(stage, ignore_errors=True)
    return [out / f.name for f in files]


def run(args: argparse.Namespace) -> int:
    found = examples()
    if not found:
        raise InputError(f"no example prototypes in {bundled_dir('examples')}; reinstall printgen")
    if args.name is None:
        for name, path in found.items():
            print(f"{name}\t{path.name}")
        return 0
    key = args.name.lower().removesuffix(".toml").removesuffix(SUFFIX)
    if key not in found:
        raise InputError(f"no example named {args.name!r}; examples: {', '.join(found)}")
    if args.out is not None:
        for f in copy_example(found[key], args.out):
            print(f)
        return 0
    if found[key].is_dir():
        for f in example_files(found[key]):
            print(f)
        print(f"(copy them with: printgen example {key} --out DIR)", file=sys.stderr)
        return 0
    data = found[key].read_bytes()
    out = getattr(sys.stdout, "buffer", None)
    if out is None:  # a text-only stream (an embedding program's)
        sys.stdout.write(data.decode("utf-8"))
        return 0
    sys.stdout.flush()
    out.write(data)  # the file's bytes, UTF-8 and its line ends, on every OS
    out.flush()
    return 0
