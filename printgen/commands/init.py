"""`printgen init FILE.toml [--force]`: write a commented prototype template (every key, its
unit, meaning and range), to edit into your own barrier."""

from __future__ import annotations

import argparse
from pathlib import Path

from printgen.commands.common import console
from printgen.errors import InputError


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("init", help="write a commented prototype template to edit")
    p.add_argument("file", type=Path, help="the prototype file to write (.toml)")
    p.add_argument("--force", action="store_true", help="replace an existing file")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from printgen.inputs.template import template_text
    from printgen.outputs import write_text

    if args.file.exists() and not args.force:
        raise InputError(f"{args.file} exists; choose another name or pass --force")
    if args.file.suffix != ".toml":
        raise InputError(f"{args.file}: give a .toml file name")
    write_text(args.file, template_text())
    console().print(f"wrote {args.file}; edit it, then: printgen targets {args.file} --scale 40")
    return 0
