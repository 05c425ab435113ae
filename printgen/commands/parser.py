"""The parser of printgen's commands (each in `printgen/commands/<name>.py`) and the text of
what the command line prints: argparse's errors as one line (`UsageError`), control
characters shown as escapes (`printable`), in the log too (`configure_logging`)."""

from __future__ import annotations

import argparse
import importlib
import logging
import re
import sys
from typing import NoReturn

import printgen
from printgen.commands import COMMAND_MODULES
from printgen.errors import PrintgenError


class UsageError(PrintgenError):
    """The command line itself is wrong: a missing or unknown option, a bad value."""


class Parser(argparse.ArgumentParser):
    """argparse, with its errors as one line and a hint (like every other error), not a
    usage block: `UsageError` for `main` to print."""

    def error(self, message: str) -> NoReturn:
        raise UsageError(f"{self.prog}: error: {message}; see `{self.prog} --help`")


class _Version(argparse.Action):
    """`--version`: the version is looked up only when asked (in a checkout it runs git)."""

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace,
                 values: object, option_string: str | None = None) -> None:
        sys.stdout.write(f"printgen {printgen.__version__}\n")  # stdout, as argparse's own
        parser.exit()


def build_parser(argv: list[str] | None = None) -> argparse.ArgumentParser:
    """The parser of every command, or with `argv` naming one (its first word that is not an
    option) of that command alone: the others' imports (scipy.optimize for calibrate, ...)
    would only delay it (each module registers the command of its own name)."""
    parser = Parser(
        prog="printgen",
        description="Stiffness-scaled, printable flexible-barrier models for flume experiments.",
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress details")
    parser.add_argument("--version", action=_Version, nargs=0,
                        help="show printgen's version, from git, and exit")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    words = [a for a in argv or [] if not a.startswith("-") or a in ("-h", "--help")]
    only = [m for m in COMMAND_MODULES if words and m.rsplit(".", 1)[-1] == words[0]]
    if not words and "--version" in (argv or []):
        return parser  # argparse prints the version and exits: no command is needed
    for name in only or COMMAND_MODULES:
        importlib.import_module(name).register(sub)
    return parser


def configure_logging(verbose: bool) -> None:
    """Log to stderr (INFO with --verbose, else WARNING), each record `printable`."""
    logging.basicConfig(level=logging.INFO if verbose else logging.WARNING)
    for handler in logging.getLogger().handlers:
        if type(handler) is logging.StreamHandler:  # basicConfig's own, not a test's capture
            handler.setFormatter(_PrintableFormatter("%(levelname)s: %(message)s"))


# C0 and C1 control characters but the newline: a path holding ESC sequences could otherwise
# set the terminal's title or clear it when an error or a warning echoes it.
_CONTROL = re.compile(r"[\x00-\x09\x0b-\x1f\x7f-\x9f]")


def printable(text: str) -> str:
    """`text` with control characters shown as escapes (`\x1b`), safe to print on a terminal."""
    return _CONTROL.sub(lambda m: f"\\x{ord(m.group()):02x}", text)


class _PrintableFormatter(logging.Formatter):
    def format(self, record: logging.LogRecord) -> str:
        return printable(super().format(record))
