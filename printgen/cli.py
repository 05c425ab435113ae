"""printgen's command line: argparse subcommands, each in `printgen/commands/<name>.py`.

A command module defines `register(subparsers)` (adds its parser and sets `func`) and the
function it sets runs it and returns an exit code. Bad input (`PrintgenError`) exits 2 with a
one-line message and no traceback.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys

from printgen.errors import PrintgenError

# One entry per command module; a module may register several subcommands.
COMMAND_MODULES = (
    "printgen.commands.targets",
    "printgen.commands.select",
    "printgen.commands.profiles",
    "printgen.commands.make",
    "printgen.commands.bench",
    "printgen.commands.calibrate",
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="printgen",
        description="Stiffness-scaled, printable flexible-barrier models for flume experiments.",
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress details")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name in COMMAND_MODULES:
        importlib.import_module(name).register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.INFO if args.verbose else logging.WARNING,
        format="%(levelname)s: %(message)s",
    )
    try:
        return int(args.func(args) or 0)
    except PrintgenError as exc:
        print(f"printgen {args.command}: error: {exc}", file=sys.stderr)
        return 2
