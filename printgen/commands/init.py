"""`printgen init FILE.toml [--force]`: write a commented prototype template (every key, its
unit, meaning and range), to edit into your own barrier."""

from __future__ import annotations

import argparse
from pathlib import Path

from printgen.commands.common import add_json_arg, console, emit_json
from printgen.run import api


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("init", help="write a commented prototype template to edit")
    p.add_argument("file", type=Path, help="the prototype file to write (.toml)")
    p.add_argument("--force", action="store_true", help="replace an existing file")
    add_json_arg(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    path = api.init(args.file, force=args.force)
    if args.json:
        emit_json({"written": str(path)})
        return 0
    console().print(f"wrote {path}; edit it, then: printgen targets {path} --scale 40")
    return 0
