"""`printgen bench solver|sweeps|gcode|parts|design|make|figures|timeline|fit|table --out DIR`:
run a benchmark of benchmarks/ (a source checkout) and write its JSON/PNG into DIR (`table`: every
row of the speed table in one JSON, benchmarks/bench_table.py). An installed wheel has no
benchmarks/: there the command is not offered (argparse lists the commands that are)."""

from __future__ import annotations

import argparse
import importlib
import sys
from pathlib import Path

from printgen.errors import InputError

ROOT = Path(__file__).resolve().parents[2]
BENCHES = ("solver", "sweeps", "gcode", "parts", "design", "make", "figures", "timeline",
           "fit", "table")


def available() -> bool:
    """True when printgen runs from a source checkout that holds the benchmarks."""
    return (ROOT / "pyproject.toml").is_file() and (ROOT / "benchmarks").is_dir()


def register(sub: argparse._SubParsersAction) -> None:
    if not available():
        return
    p = sub.add_parser("bench", help="run a benchmark (speed against error) into a folder")
    p.add_argument("name", choices=BENCHES)
    p.add_argument("--out", type=Path, default=Path("benchmarks/results"))
    p.add_argument("--json", action="store_true",
                   help="print the report as JSON (the files in --out hold it all)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if not (ROOT / "benchmarks" / f"bench_{args.name}.py").is_file():
        raise InputError(f"benchmarks/bench_{args.name}.py not found under {ROOT}; the "
                         "benchmarks live in a source checkout of printgen")
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    module = importlib.import_module(f"benchmarks.bench_{args.name}")
    extra = ["--json"] if args.json else []
    return int(module.main(["--out", str(args.out), *extra]) or 0)
