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
from printgen.run import api


def _record(args: argparse.Namespace) -> dict:
    """`--json`: the examples (name -> file or folder name), or the one named: its files
    (copied ones with --out) and, for a single prototype file, its text."""
    if args.name is None:
        return {"examples": {name: path.name for name, path in api.examples().items()}}
    ex, written = _example(args)
    rec: dict = {"name": ex.name, "source": ex.path.name, "files": [str(f) for f in ex.files]}
    if not written and args.out is None and not ex.is_folder:
        rec["text"] = ex.path.read_text("utf-8")
    return rec


def _example(args: argparse.Namespace) -> tuple[api.Example, bool]:
    """The example asked, copied (--out) or written into FILE (the notebook: its default
    name without FILE), and whether it was written into a file."""
    ex = api.example(args.name, out=args.out, file=args.file)
    if args.file is None and args.out is None and ex.default_file is not None:
        ex = api.example(args.name, file=ex.default_file)
    return ex, args.file is not None or ex.default_file is not None and args.out is None


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("example", help="print or write a bundled example (a prototype, the "
                                          "notebook), or copy an example folder")
    p.add_argument("name", nargs="?", help="which example (none: list them)")
    p.add_argument("file", nargs="?", type=Path,
                   help="write a one-file example (a prototype, the notebook) into this new "
                        "file instead of printing it (the notebook: by default into its own "
                        "name here)")
    p.add_argument("--out", "-o", type=Path, metavar="DIR",
                   help="copy the example's files into DIR (a new folder) instead of printing")
    add_json_arg(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if args.json:
        emit_json(_record(args))
        return 0
    if args.name is None:
        for name, path in api.examples().items():
            print(f"{name}\t{path.name}")
        return 0
    ex, written = _example(args)
    if written:
        print(ex.files[0])
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
