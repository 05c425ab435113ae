"""Arguments and output helpers shared by the commands: prototype + scale, JSON, tables."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from rich.console import Console
from rich.table import Table

from printgen.inputs.profiles import profile_name
from printgen.report.jsonout import dumps


def add_prototype_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("prototype", help="prototype barrier TOML (see examples/)")
    p.add_argument("--scale", "-s", type=float, required=True, metavar="LAMBDA",
                   help="geometric scale lambda = prototype / model, >= 1 (1:40 -> 40)")


def check_profile_args(args: argparse.Namespace, *options: str) -> None:
    """ProfileError now, before any work, when --printer, --materials, ... is not a plain
    profile name (a path, a glob, a hidden file)."""
    for opt in options:
        value = getattr(args, opt, None)
        for name in value if isinstance(value, (list, tuple)) else [value]:
            if name is not None:
                profile_name(name, f"--{opt}")


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
