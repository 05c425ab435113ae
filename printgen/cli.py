"""printgen's command line: argparse subcommands, each in `printgen/commands/<name>.py`.

A command module defines `register(subparsers)` (adds its parser and sets `func`) and the
function it sets runs it and returns an exit code. Bad input (`PrintgenError`) and a solve that
did not converge (`SolverError`) exit 2 with a one-line message and no traceback.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import os
import re
import sys
from concurrent.futures.process import BrokenProcessPool
from typing import NoReturn

import printgen
from printgen.errors import PrintgenError, TimeLimitError, reported
from printgen.executor.signals import Interrupted, signals_raise
from printgen.outputs import describe_os_error, os_error_exit_code, tracking_swaps

# One entry per command module; a module may register several subcommands.
COMMAND_MODULES = (
    "printgen.commands.targets",
    "printgen.commands.select",
    "printgen.commands.profiles",
    "printgen.commands.make",
    "printgen.commands.design",
    "printgen.commands.series",
    "printgen.commands.verify",
    "printgen.commands.check",
    "printgen.commands.panel",
    "printgen.commands.testpieces",
    "printgen.commands.bench",
    "printgen.commands.calibrate",
    "printgen.commands.example",
    "printgen.commands.init",
)


class UsageError(PrintgenError):
    """The command line itself is wrong: a missing or unknown option, a bad value."""


class Parser(argparse.ArgumentParser):
    """argparse, with its errors as one line and a hint (like every other error), not a
    usage block: `UsageError` for `main` to print."""

    def error(self, message: str) -> NoReturn:
        raise UsageError(f"{self.prog}: error: {message}; see `{self.prog} --help`")


def build_parser(argv: list[str] | None = None) -> argparse.ArgumentParser:
    """The parser of every command, or with `argv` naming one (its first word that is not an
    option) of that command alone: the others' imports (scipy.optimize for calibrate, ...)
    would only delay it (each module registers the command of its own name)."""
    parser = Parser(
        prog="printgen",
        description="Stiffness-scaled, printable flexible-barrier models for flume experiments.",
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress details")
    parser.add_argument("--version", action="version", version=f"printgen {printgen.__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    words = [a for a in argv or [] if not a.startswith("-") or a in ("-h", "--help")]
    only = [m for m in COMMAND_MODULES if words and m.rsplit(".", 1)[-1] == words[0]]
    if not words and "--version" in (argv or []):
        return parser  # argparse prints the version and exits: no command is needed
    for name in only or COMMAND_MODULES:
        importlib.import_module(name).register(sub)
    return parser


REPORT_URL = "the printgen maintainers (an issue with the command line and this line)"


def main(argv: list[str] | None = None) -> int:
    """Run one command; return its exit code. No traceback reaches the user: bad input exits
    2, a signal 128 + its number (130 Ctrl-C, 143 SIGTERM), anything unexpected 1 with a hint
    to report it (PRINTGEN_DEBUG=1 re-raises it, traceback and all)."""
    argv = sys.argv[1:] if argv is None else [str(a) for a in argv]
    try:
        parser = build_parser(argv)
        args = parser.parse_args(argv)
    except UsageError as exc:
        return _fail(str(exc), 2)
    except KeyboardInterrupt:
        print("printgen: interrupted (Ctrl-C)", file=sys.stderr)
        return 130
    args.argv = ["printgen", *argv]
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING)
    for handler in logging.getLogger().handlers:
        if type(handler) is logging.StreamHandler:  # basicConfig's own, not a test's capture
            handler.setFormatter(_PrintableFormatter("%(levelname)s: %(message)s"))
    return run_command(args, f"printgen {args.command}")


def run_command(args: argparse.Namespace, name: str) -> int:
    """Call the command's function and turn every way it can end into one line and a code."""
    with tracking_swaps() as replaced:
        try:
            with signals_raise():
                return int(args.func(args) or 0)
        except TimeLimitError as exc:
            return _fail(f"{name}: {exc}", 4)  # commands/make.py EXIT_TIME_LIMIT
        except PrintgenError as exc:
            return _fail(f"{name}: error: {exc}", 2)
        except Interrupted as exc:
            return _fail(_stopped(name, exc.name, replaced), exc.exit_code)
        except KeyboardInterrupt:
            return _fail(_stopped(name, "SIGINT", replaced), 130)
        except OSError as exc:
            return _fail(f"{name}: error: {describe_os_error(exc)}", os_error_exit_code(exc))
        except MemoryError:
            return _fail(f"{name}: error: out of memory; use a coarser mesh or a larger machine",
                         1)
        except BrokenProcessPool:
            return _fail(f"{name}: error: a worker process died (killed, or out of memory: see "
                         "`dmesg`); outputs left as they were; try again, or a coarser mesh", 1)
        except Exception as exc:
            if reported(exc):  # the solver's SolverError, not a PrintgenError
                return _fail(f"{name}: error: {exc}", 2)
            if os.environ.get("PRINTGEN_DEBUG"):
                raise
            text = " ".join(str(exc).split())[:300]
            return _fail(f"{name}: internal error: {type(exc).__name__}: {text}; this is a bug "
                         f"in printgen, please report it to {REPORT_URL} "
                         "(PRINTGEN_DEBUG=1 shows the traceback)", 1)


def _stopped(name: str, signal_name: str, replaced: list) -> str:
    """The line for a run stopped by a signal: before or after its folder was swapped in."""
    if replaced:
        return (f"{name}: stopped by {signal_name} after the run was complete: {replaced[-1]} "
                "holds its new outputs (printgen check verifies them)")
    return f"{name}: stopped by {signal_name}; outputs left as they were"


def _fail(line: str, code: int) -> int:
    print(printable(line), file=sys.stderr)
    return code


# C0 and C1 control characters but the newline: a path holding ESC sequences could otherwise
# set the terminal's title or clear it when an error or a warning echoes it.
_CONTROL = re.compile(r"[\x00-\x09\x0b-\x1f\x7f-\x9f]")


def printable(text: str) -> str:
    """`text` with control characters shown as escapes (`\x1b`), safe to print on a terminal."""
    return _CONTROL.sub(lambda m: f"\\x{ord(m.group()):02x}", text)


class _PrintableFormatter(logging.Formatter):
    def format(self, record: logging.LogRecord) -> str:
        return printable(super().format(record))
