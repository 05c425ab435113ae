"""Arguments and output helpers shared by the commands: prototype + scale, JSON, tables."""

from __future__ import annotations

import argparse
import contextlib
import math
import sys
from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

from rich.console import Console
from rich.table import Table

from printgen.inputs.profiles import profile_name
from printgen.report.jsonout import dumps

if TYPE_CHECKING:
    from printgen.run.options import RunOptions

EXIT_INCOMPLETE = 3  # outputs written, but the verdict rests on fewer load levels than asked


def incomplete_code(record: dict[str, Any], command: str) -> int:
    """EXIT_INCOMPLETE, with one line on stderr, when the run's verdict rests on fewer load
    levels than asked (the others did not converge); else 0. For `make` and `verify`."""
    ver = record.get("verification") or {}
    if ver.get("complete") is not False:
        return 0
    Console(stderr=True, highlight=False).print(
        f"printgen {command}: the verdict rests on {ver['levels_compared']} of "
        f"{ver['levels_asked']} load levels (the others did not converge: see the report); "
        f"exit {EXIT_INCOMPLETE}")
    return EXIT_INCOMPLETE


def add_prototype_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("prototype", help="prototype barrier TOML (see examples/)")
    p.add_argument("--scale", "-s", type=float, required=True, metavar="LAMBDA",
                   help="geometric scale lambda = prototype / model, >= 1 (1:40 -> 40)")


def add_time_limit_arg(p: argparse.ArgumentParser, default: float | None = None) -> None:
    """--time-limit SECONDS: the run's estimate must fit it (printgen.run.budget); `default`
    None: a minute (`DEFAULT_LIMIT_S`)."""
    from printgen.run.budget import DEFAULT_LIMIT_S

    limit = DEFAULT_LIMIT_S if default is None else default
    p.add_argument("--time-limit", type=seconds, default=limit, metavar="SECONDS",
                   help=f"refuse runs estimated longer than this (default {limit:g} s)")


def seconds(text: str) -> float:
    """An argparse type: a positive, finite number of seconds (0, -1 and nan are refused, not
    taken as the default)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number of seconds") from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"{text} must be a positive number of seconds, e.g. "
                                         "600")
    return value


def check_profile_args(args: argparse.Namespace, *options: str) -> None:
    """ProfileError now, before any work, when --printer, --materials, ... is not a plain
    profile name (a path, a glob, a hidden file)."""
    for opt in options:
        value = getattr(args, opt, None)
        for name in value if isinstance(value, (list, tuple)) else [value]:
            if name is not None:
                profile_name(name, f"--{opt}")
def add_load_args(p: argparse.ArgumentParser, what: str, *, several: bool = False) -> None:
    """--load NAME (a load case of printgen/barrier/loads), its alias --drag, --load-param
    KEY=VALUE (a parameter of the chosen case, e.g. the jam's porosity) and, with `several`,
    --loads A,B (each case's expected readings side by side)."""
    from printgen.barrier.loads import case_names

    p.add_argument("--load", choices=case_names(), default=None, help=load_help(what))
    p.add_argument("--drag", action="store_const", dest="load", const="drag",
                   help="the same as --load drag")
    p.add_argument("--load-param", action="append", default=[], metavar="KEY=VALUE",
                   help="a parameter of the load case(s), e.g. porosity=0.4 for jam "
                        "(docs/physics.md: Load cases); repeat for several")
    if several:
        p.add_argument("--loads", type=load_list, default=(), metavar="A,B",
                       help="also write each load case's expected readings "
                            "(expected-readings-<case>.csv), e.g. hydrostatic,jam; the "
                            "verification runs under --load, or the first of these")


def load_help(what: str) -> str:
    """--load's help: every registered load case with its title, the default named, so a
    new case module is listed without editing the command line."""
    from printgen.barrier.loads import DEFAULT, load_cases

    cases = "; ".join(f"{c.name}: {c.title}" for c in load_cases().values())
    return f"{what} under this load case (default {DEFAULT}; {cases})".replace("%", "%%")


def load_list(text: str) -> tuple[str, ...]:
    """--loads: comma-separated load case names, each a known one."""
    from printgen.barrier.loads import case_names

    names = tuple(x.strip() for x in text.split(",") if x.strip())
    bad = [x for x in names if x not in case_names()]
    if bad or not names:
        raise argparse.ArgumentTypeError(f"{text!r}: give load cases from "
                                         f"{', '.join(case_names())}, comma-separated")
    return names


def load_specs(args: argparse.Namespace) -> tuple[str | None, tuple[str, ...]]:
    """(the verification's load case, every case of --loads) as specs with --load-param's
    values; InputError for a parameter no chosen case has or a value out of its range."""
    from printgen.barrier.loads import get_load, with_params
    from printgen.errors import InputError

    listed = tuple(getattr(args, "loads", ()) or ())
    main = args.load or (listed[0] if listed else None)
    params = list(args.load_param)
    chosen = [main or get_load(None).name, *listed]
    keys = {p.name for c in chosen for p in get_load(c).params}
    for item in params:
        if item.partition("=")[0].strip() not in keys:
            raise InputError(f"--load-param {item}: none of the load cases "
                             f"{', '.join(dict.fromkeys(chosen))} has that parameter; give one "
                             "of theirs (docs/physics.md: Load cases)")

    def spec(name: str) -> str:
        own = {p.name for p in get_load(name).params}
        return with_params(name, [x for x in params if x.partition("=")[0].strip() in own])

    return (spec(main) if main else None), tuple(spec(x) for x in listed)


def run_options(args: argparse.Namespace) -> RunOptions:
    """The run's options record from the command line: every option of it the command has
    (the load cases as specs with --load-param's values, `load_specs`), and the command line
    itself; what the command does not give keeps the record's default."""
    from printgen.run.options import RunOptions

    given = {"printer": "printer", "step": "step", "pdf": "pdf", "paper": "paper",
             "design_file": "design",
             "time_limit_s": "time_limit", "force": "force", "scheduler": "scheduler",
             "workers": "workers", "serial": "serial"}
    kw = {field: getattr(args, arg) for field, arg in given.items()
          if getattr(args, arg, None) is not None}
    if hasattr(args, "load"):
        load, loads = load_specs(args)
        kw.update({"loads": loads} | ({"load": load} if load is not None else {}))
    return RunOptions(command=getattr(args, "argv", None), **kw)


def add_json_arg(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", action="store_true", help="print machine-readable JSON")


def emit_json(obj: Any) -> None:
    sys.stdout.write(dumps(obj))


def console() -> Console:
    return Console(width=max(140, Console().width), highlight=False)


def table(title: str, columns: list[str], rows: list[list[str]]) -> Table:
    t = Table(title=title, title_justify="left", show_lines=False)
    for i, c in enumerate(columns):
        t.add_column(c, justify="left" if i == 0 else "right")
    for r in rows:
        t.add_row(*r)
    return t


def fmt(v: float | None, spec: str = ".4g") -> str:
    return "-" if v is None else format(v, spec)


class _Silent:
    """The status line's stand-in off a terminal: its text goes nowhere."""

    def update(self, _text: str) -> None:
        pass


class _Line:
    """The run's current step, one line on the terminal, drawn again when it changes."""

    def __init__(self, live) -> None:
        self.live = live

    def update(self, text: str) -> None:
        from rich.text import Text

        self.live.update(Text(text), refresh=True)


@contextlib.contextmanager
def spinner(text: str) -> Iterator:
    """The run's current step on stderr while a command runs (`make`, `verify`, `series`),
    when stderr is a terminal (erased at the end); elsewhere (a log, a pipe, a benchmark)
    nothing. Drawn when the text changes, by no thread of its own (not rich's animated
    spinner, which refreshes from one): a process running a thread starts its workers from a
    fork server (printgen.executor.start.start_method), which imports what the jobs need
    again, instead of forking them with it imported (make: its helper process; verify: its
    fit's workers; series: the cases' workers, whose progress bar, once they run, is animated)."""
    err = Console(stderr=True, highlight=False)
    if not err.is_terminal:
        yield _Silent()
        return
    from rich.live import Live
    from rich.text import Text

    with Live(Text(text), console=err, auto_refresh=False, transient=True) as live:
        yield _Line(live)
