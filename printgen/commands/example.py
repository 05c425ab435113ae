"""`printgen example [NAME] [FILE] [--out DIR]`: print a bundled example prototype, e.g.
`printgen example realistic > proto.toml`, or write it into FILE (`printgen example realistic
proto.toml`); write the example notebook (`printgen example notebook [FILE]`, default
realistic_1_40.ipynb here); or copy a bundled example folder (the paper's printed design and its
measured test: `printgen example paper_1_40 --out paper`); without NAME, list them."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from printgen.commands.common import add_json_arg, emit_json
from printgen.errors import InputError
from printgen.inputs.examples import NOTEBOOK, Example, write_example
from printgen.run import api


def _record(args: argparse.Namespace) -> dict:
    """`--json`: the examples (name -> file or folder name), or the one named: its files
    (copied ones with --out) and, for a single prototype file, its text."""
    if args.name is None:
        return {"examples": {name: path.name for name, path in api.examples().items()}}
    ex = api.example(args.name, out=args.out)
    rec: dict = {"name": ex.name, "source": ex.path.name, "files": [str(f) for f in ex.files]}
    written = _written(ex, args)
    if written is not None:
        rec["files"] = [str(written)]
    elif args.out is None and not ex.is_folder:
        rec["text"] = ex.path.read_text("utf-8")
    return rec


def _written(ex: Example, args: argparse.Namespace) -> Path | None:
    """The file a one-file example was written into (FILE; the notebook's default name
    without one), or None when it is printed or copied (--out)."""
    if args.file is None and (ex.name != NOTEBOOK[0] or args.out is not None):
        return None
    return write_example(ex, args.file or NOTEBOOK[1])


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("example", help="print a bundled example prototype (TOML) to stdout")
    p.add_argument("name", nargs="?", help="which example (none: list them)")
    p.add_argument("file", nargs="?", type=Path,
                   help="write a one-file example (a prototype, the notebook) into this new "
                        f"file instead of printing it (the notebook's default: {NOTEBOOK[1]})")
    p.add_argument("--out", "-o", type=Path, metavar="DIR",
                   help="copy the example's files into DIR (a new folder) instead of printing")
    add_json_arg(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if args.file is not None and args.out is not None:  # before --out copies anything
        raise InputError("give FILE or --out DIR, not both")
    if args.json:
        emit_json(_record(args))
        return 0
    if args.name is None:
        for name, path in api.examples().items():
            print(f"{name}\t{path.name}")
        return 0
    ex = api.example(args.name, out=args.out)
    written = _written(ex, args)
    if written is not None:
        print(written)
        return 0
    if args.out is not None or ex.is_folder:
        for f in ex.files:
            print(f)
        if args.out is None:
            print(f"(copy them with: printgen example {ex.name} --out DIR)", file=sys.stderr)
        return 0
    data = ex.path.read_bytes()
    out = getattr(sys.stdout, "buffer", None)
    if out is None:  # a text-only stream (an embedding program's)
        sys.stdout.write(data.decode("utf-8"))
        return 0
    sys.stdout.flush()
    out.write(data)  # the file's bytes, UTF-8 and its line ends, on every OS
    out.flush()
    return 0
