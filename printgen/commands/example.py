"""`printgen example [NAME]`: print a bundled example prototype, e.g.
`printgen example realistic > proto.toml`; without NAME, list them."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from printgen.errors import InputError
from printgen.inputs.profiles import bundled_dir

SUFFIX = "_barrier"  # realistic_barrier.toml is the example `realistic`


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("example", help="print a bundled example prototype (TOML) to stdout")
    p.add_argument("name", nargs="?", help="which example (none: list them)")
    p.set_defaults(func=run)


def examples() -> dict[str, Path]:
    """Example name -> its TOML file, from the package data (or the checkout's examples/)."""
    files = sorted(bundled_dir("examples").glob("*.toml"))
    return {f.stem.removesuffix(SUFFIX): f for f in files}


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
    data = found[key].read_bytes()
    out = getattr(sys.stdout, "buffer", None)
    if out is None:  # a text-only stream (an embedding program's)
        sys.stdout.write(data.decode("utf-8"))
        return 0
    sys.stdout.flush()
    out.write(data)  # the file's bytes, UTF-8 and its line ends, on every OS
    out.flush()
    return 0
