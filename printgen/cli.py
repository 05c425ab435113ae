"""printgen's command line: argparse subcommands, each in `printgen/commands/<name>.py` (the
parser: `printgen.commands.parser`).

A command module defines `register(subparsers)` (adds its parser and sets `func`) and the
function it sets runs it and returns an exit code. Bad input (`PrintgenError`) and a solve that
did not converge (`SolverError`) exit 2 with a one-line message and no traceback.

A signal (SIGINT, SIGTERM, SIGHUP) ends the command with one line and exit 128 + its number
whenever it comes: `main` installs the handler first thing, before the commands' imports (this
module imports nothing heavy), and once the outcome is known `_Outcome.at_end` ends the process
at once, a line only if none was printed yet.
"""

from __future__ import annotations

import atexit
import contextlib
import os
import signal
import sys
from typing import TYPE_CHECKING, Any

from printgen import commands
from printgen.executor import signals
from printgen.executor.signals import Interrupted

if TYPE_CHECKING:
    import argparse
    from pathlib import Path

    from printgen.commands.parser import Parser, UsageError, build_parser, printable  # noqa: F401

COMMAND_MODULES = commands.COMMAND_MODULES  # the one list, in printgen.commands
COMMANDS = frozenset(m.rsplit(".", 1)[-1] for m in COMMAND_MODULES)  # each registers its own
PARSER_NAMES = ("Parser", "UsageError", "build_parser", "printable")  # `__getattr__`'s
REPORT_URL = "the printgen maintainers (an issue with the command line and this line)"


def __getattr__(name: str) -> Any:
    """The parser's names (`printgen.commands.parser`), imported when first asked for."""
    if name in PARSER_NAMES:
        from printgen.commands import parser

        return getattr(parser, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def main(argv: list[str] | None = None) -> int:
    """Run one command; return its exit code. No traceback reaches the user: bad input exits
    2, a signal 128 + its number (130 Ctrl-C, 143 SIGTERM), anything unexpected 1 with a hint
    to report it (PRINTGEN_DEBUG=1 re-raises it, traceback and all).

    Without `argv` (the console script, `python -m printgen`) the process is the command's:
    the signal handlers stay after the return, so that a signal while Python shuts down (its
    threads joined, its exit hooks run) still ends it with the line and the code
    (`_Outcome.at_end`), and the last exit hook ends it (`_Outcome.exit_now`). With `argv` (a
    test, a notebook) they are restored."""
    process = argv is None
    argv = sys.argv[1:] if argv is None else [str(a) for a in argv]
    outcome = _Outcome(command_name(argv))
    if process:
        atexit.register(outcome.exit_now)  # the first exit hook: run last
        signals.ending(outcome.at_end)
    with signals.signals_raise(restore=not process):
        try:
            if process:  # the libraries' temporary files in the run's own folder
                from printgen.outputs.tempdir import private_tempdir

                private_tempdir()
            outcome.code = _parse_and_run(argv, outcome)
        except Interrupted as exc:  # in the imports or the parsing, or just after the command
            outcome.code = outcome.stopped(exc.signum)
        except SystemExit as exc:  # --help, --version
            outcome.code = exc.code if isinstance(exc.code, int) else 0
            raise
    return outcome.code


def command_name(argv: list[str]) -> str:
    """'printgen COMMAND' from the command line's first word when it names a command, before
    any command is imported (the line of a signal during the imports names it too)."""
    words = [a for a in argv if not a.startswith("-")]
    return f"printgen {words[0]}" if words and words[0] in COMMANDS else "printgen"


def _parse_and_run(argv: list[str], outcome: _Outcome) -> int:
    from printgen.commands.parser import UsageError, build_parser, configure_logging

    try:
        args = build_parser(argv).parse_args(argv)
    except UsageError as exc:
        return outcome.fail(str(exc), 2)
    args.argv = ["printgen", *argv]
    configure_logging(args.verbose)
    outcome.name = f"printgen {args.command}"
    return run_command(args, outcome.name, outcome)


def run_command(args: argparse.Namespace, name: str, outcome: _Outcome | None = None) -> int:
    """Call the command's function and turn every way it can end into one line and a code.
    A signal seen during the command wins over the error it ended in (a pool it broke, a
    library that turned it into another exception) and over a run a library let go on (it
    swallowed the signal): the line says whether the run's folder was swapped in."""
    from printgen.outputs import tracking_swaps

    outcome = outcome or _Outcome(name)
    with tracking_swaps() as outcome.replaced:
        try:
            with signals.signals_raise():  # (already, under `main`)
                code = int(args.func(args) or 0)
                signals.raise_received()
            return code
        except Interrupted as exc:
            return outcome.stopped(exc.signum)
        except KeyboardInterrupt:
            return outcome.stopped(signal.SIGINT)
        except Exception as exc:
            if signals.received() is not None:
                return outcome.stopped(signals.received() or 0)
            return outcome.failed(exc)


class _Outcome:
    """How the command ended: its name, exit code (None while it runs), the output folders it
    swapped in, and whether its one line is on stderr (at most one is printed)."""

    def __init__(self, name: str) -> None:
        self.name = name
        self.code: int | None = None
        self.replaced: list[Path] = []
        self.said = False

    def fail(self, line: str, code: int) -> int:
        """Print `line` on stderr unless a line was printed; return `code`."""
        from printgen.commands.parser import printable

        if not self.said:
            self.said = True
            print(printable(line), file=sys.stderr)
        return code

    def stopped(self, signum: int) -> int:
        """The line of a run stopped by `signum`: before or after its folder was swapped in."""
        stop = signal.Signals(signum).name
        if self.replaced:
            line = (f"{self.name}: stopped by {stop} after the run was complete: "
                    f"{self.replaced[-1]} holds its new outputs (printgen check verifies them)")
        else:
            line = f"{self.name}: stopped by {stop}; outputs left as they were"
        return self.fail(line, 128 + signum)

    def failed(self, exc: Exception) -> int:
        """The line and code of an error the command ended in."""
        from concurrent.futures.process import BrokenProcessPool

        from printgen.errors import PrintgenError, TimeLimitError, reported
        from printgen.outputs import describe_os_error, os_error_exit_code

        name = self.name
        if isinstance(exc, TimeLimitError):
            return self.fail(f"{name}: {exc}", 4)  # commands/make.py EXIT_TIME_LIMIT
        if isinstance(exc, PrintgenError) or reported(exc):  # reported: the solver's SolverError
            return self.fail(f"{name}: error: {exc}", 2)
        if isinstance(exc, OSError):
            return self.fail(f"{name}: error: {describe_os_error(exc)}", os_error_exit_code(exc))
        if isinstance(exc, MemoryError):
            return self.fail(f"{name}: error: out of memory; use a coarser mesh or a larger "
                             "machine", 1)
        if isinstance(exc, BrokenProcessPool):
            return self.fail(f"{name}: error: a worker process died (killed, or out of memory: "
                             "see `dmesg`); outputs left as they were; try again, or a coarser "
                             "mesh", 1)
        if os.environ.get("PRINTGEN_DEBUG"):
            raise exc
        text = " ".join(str(exc).split())[:300]
        return self.fail(f"{name}: internal error: {type(exc).__name__}: {text}; this is a bug "
                         f"in printgen, please report it to {REPORT_URL} "
                         "(PRINTGEN_DEBUG=1 shows the traceback)", 1)

    def at_end(self, signum: int) -> None:
        """A signal once the outcome is known (`signals.ending`): end the process now, with
        the command's line and code, or this signal's when the command ended well and said
        nothing. While the command runs, nothing: the signal raises `Interrupted`."""
        if self.code is None:
            return
        code = self.code if self.said else self.stopped(signum)
        _exit(code)

    def exit_now(self) -> None:
        """The last exit hook of the command line's process (the others ran: workers reaped,
        temporary folders removed): end it now with its code. Python's finalisation, which
        would follow, resets the signal handlers to the defaults first: a signal then would
        kill the process with no line, or be lost."""
        if self.code is not None:  # else an exception is on its way out (PRINTGEN_DEBUG)
            _exit(self.code)


def _exit(code: int) -> None:
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):  # a closed pipe: the code still goes out
            stream.flush()
    os._exit(code)
