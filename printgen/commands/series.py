"""`printgen series PROTOTYPE --scales 1,10,30,50,100 [--materials petg tpe] [--load NAME]
[--solver-net KEY=VALUE,...] [--out DIR] [--scheduler ADDRESS | --workers N | --serial]
[--json]`: the virtual scale series (printgen.run.series)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from printgen.commands.common import (
    add_json_arg,
    add_load_args,
    add_time_limit_arg,
    check_profile_args,
    console,
    emit_json,
    run_options,
    spinner,
    table,
)
from printgen.errors import InputError

DEFAULT_SCALES = "1,10,30,50,100"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("series", help="the virtual scale series: the prototype at 1:lambda with "
                                      "its material, E/lambda and printable materials")
    p.add_argument("prototype", help="prototype barrier TOML (see examples/)")
    p.add_argument("--scales", default=DEFAULT_SCALES, metavar="L1,L2,...",
                   help=f"scales lambda, each > 0 (default {DEFAULT_SCALES})")
    p.add_argument("--materials", nargs="+", default=[], metavar="NAME",
                   help="material profiles for a row each (e.g. petg tpe)")
    add_load_args(p, "the series")
    p.add_argument("--solver-net", metavar="KEY=VALUE,...",
                   help="solver scene options: mounting=walls|eyelets, sensors=on|off (1 N "
                        "wires on the models), pressure=flow|normal, slack=0.01, "
                        "orientation=short|long")
    p.add_argument("--out", "-o", type=Path, help="output folder (default out/<name>-series)")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="a running Dask scheduler (tcp://host:8786)")
    where.add_argument("--serial", action="store_true", default=None,
                       help="run in this process (default: serial below 12 cases, this "
                            "machine's worker processes above)")
    p.add_argument("--workers", type=int, help="worker processes on this machine")
    add_time_limit_arg(p)
    p.add_argument("--force", action="store_true",
                   help="replace an output folder printgen did not write")
    add_json_arg(p)
    p.set_defaults(func=run)


def _scales(text: str) -> list[float]:
    try:
        return [float(v) for v in text.split(",") if v.strip()]
    except ValueError as exc:
        raise InputError(f"--scales {text!r}: expected comma-separated numbers, e.g. "
                         f"{DEFAULT_SCALES}") from exc


def run(args: argparse.Namespace) -> int:
    from printgen.run import api

    check_profile_args(args, "materials")
    out = args.out or Path("out") / f"{Path(args.prototype).stem}-series"
    with spinner("reading inputs") as status:
        res = api.series(args.prototype, _scales(args.scales), materials=args.materials,
                         net=args.solver_net, out=out, options=run_options(args),
                         progress=lambda s: status.update(f"{s} ..."), bar=not args.json)
    if args.json:
        emit_json(res.record)
        return 0
    show(res, out)
    return 0


def show(res, out: Path) -> None:
    from printgen.report.series import table_rows

    s = res.series
    short = {r.label: r.short for r in s.rows}
    c = console()
    c.print(table(f"Scale series of {s.prototype} ({s.scene}, {res.record['load_case']}, "
                  f"h/h_B = {res.record['level']:g}; ratio = value / prototype)",
                  ["row", "lambda", "deflection", "lowering", "elong. mid", "defl. ratio",
                   "low. ratio", "elong. ratio", "Pi = F/EA", "law dep. defl", "law dep. elong"],
                  [[short[r[0]], *r[1:]] for r in table_rows(s)]))
    for text in s.sentences.values():
        c.print(f"- {text}")
    c.print(f"ran on {res.where}; {len(res.files)} files in {out}/ ; open "
            f"{out / 'report.html'}")
    sys.stdout.flush()
