"""`printgen design PROTOTYPE --scale 40 [--objective deformation|stiffness] [--out DIR]
[--scheduler ADDRESS | --workers N | --serial] [--scales 20,30,40,60] [bounds] [--json]`:
search the printable net that deforms most like the prototype (see printgen.search.nets)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from printgen.commands.common import (
    add_json_arg,
    add_time_limit_arg,
    check_profile_args,
    console,
    emit_json,
    run_options,
    table,
)
from printgen.errors import InputError
from printgen.executor.dask import check_address
from printgen.run import api
from printgen.run.budget import DESIGN_LIMIT_S
from printgen.run.search import DesignRun, SearchOptions
from printgen.search.choice import short
from printgen.search.nets import OBJECTIVES, VERIFY_NETS, SearchResult

SHOW = 10  # Pareto members shown per scale in the table (all are in report.json)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("design", help="search material x strand x diamond mesh x border for the "
                                      "net that deforms like the prototype (parallel sweeps)")
    p.add_argument("prototype", help="prototype barrier TOML (see examples/)")
    p.add_argument("--scale", "-s", type=float, metavar="LAMBDA",
                   help="geometric scale lambda (1:40 -> 40); or give --scales")
    p.add_argument("--scales", metavar="L1,L2,...", help="scale series: best net at each scale")
    p.add_argument("--objective", choices=OBJECTIVES, default="deformation",
                   help="deformation: solver mismatch of the best few (default); stiffness: "
                        "membrane-law error only (fast, no solver)")
    p.add_argument("--out", "-o", type=Path, help="output folder (default out/<name>-design)")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="a running Dask scheduler (tcp://host:8786), for work that may "
                            "leave this machine; default: this machine's worker processes")
    where.add_argument("--serial", action="store_true", help="run in this process")
    p.add_argument("--workers", type=int, help="worker processes on this machine (default: every "
                                                "core)")
    p.add_argument("--materials", nargs="+", metavar="NAME", help="materials to search")
    p.add_argument("--mesh-x-mm", metavar="LO:HI", help="bounds of the diagonal across (mm)")
    p.add_argument("--mesh-y-mm", metavar="LO:HI", help="bounds of the diagonal up (mm)")
    p.add_argument("--mesh-tolerance", type=float, metavar="F",
                   help="default bounds: each diagonal within +-F of the scaled prototype's "
                        "(default 0.25)")
    p.add_argument("--border-beads", metavar="N1,N2,...",
                   help="border widths in beads, even (default 2,4)")
    p.add_argument("--printer", help="printer profile (default: the prototype's [model] choice)")
    p.add_argument("--verify-nets", type=int, default=VERIFY_NETS, metavar="N",
                   help=f"nets verified by the solver, each with every border (default "
                        f"{VERIFY_NETS})")
    p.add_argument("--level-step", type=float, metavar="R",
                   help="load-level step of the solver stage (default: the verification's 0.05)")
    add_time_limit_arg(p, DESIGN_LIMIT_S)
    add_json_arg(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    check_profile_args(args, "printer", "materials")
    if args.scheduler:
        check_address(args.scheduler)
    scales = _scales(args)
    if len(scales) > 1 and (args.mesh_x_mm or args.mesh_y_mm):
        raise InputError("--mesh-x-mm/--mesh-y-mm are millimetres at one scale; with --scales "
                         "use --mesh-tolerance")
    opts = SearchOptions(
        objective=args.objective, materials=tuple(args.materials) if args.materials else None,
        mesh_x_mm=_range(args.mesh_x_mm, "--mesh-x-mm"),
        mesh_y_mm=_range(args.mesh_y_mm, "--mesh-y-mm"), mesh_tolerance=args.mesh_tolerance,
        border_beads=_ints(args.border_beads, "--border-beads"), printer=args.printer,
        verify_nets=args.verify_nets, level_step=args.level_step)
    out = args.out or Path("out") / f"{Path(args.prototype).stem}-design"
    result = api.search_nets(args.prototype, scales, options=opts, run=run_options(args),
                             progress=not args.json, out=out, main_scale=args.scale)
    if args.json:
        emit_json(result.record)
        return 0
    show(result, out, result.files)
    return 0


def _scales(args: argparse.Namespace) -> list[float]:
    scales = [float(x) for x in _floats(args.scales, "--scales")] if args.scales else []
    if args.scale is not None and args.scale not in scales:
        scales.insert(0, args.scale)
    if not scales:
        raise InputError("give --scale LAMBDA (e.g. 40) or --scales 20,30,40,60")
    return scales


def _floats(text: str, opt: str) -> list[float]:
    try:
        return [float(v) for v in text.split(",") if v.strip()]
    except ValueError as exc:
        raise InputError(f"{opt} {text!r}: expected comma-separated numbers") from exc


def _ints(text: str | None, opt: str) -> tuple[int, ...] | None:
    if text is None:
        return None
    vals = _floats(text, opt)
    if not vals or any(v != int(v) or v < 1 for v in vals):
        raise InputError(f"{opt} {text!r}: expected whole numbers >= 1, e.g. 1,2,3")
    return tuple(int(v) for v in vals)


def _range(text: str | None, opt: str) -> tuple[float, float] | None:
    if text is None:
        return None
    lo, sep, hi = text.partition(":")
    try:
        if not sep:
            raise ValueError
        return float(lo), float(hi)
    except ValueError as exc:
        raise InputError(f"{opt} {text!r}: expected LO:HI in mm, e.g. 12:20") from exc


def show(result: DesignRun, out: Path, files: list[str]) -> None:
    c = console()
    for r in result.results:
        sc = r.screened
        shown = shown_rows(r)
        rows = []
        for i in shown:
            s = sc[i]
            mark = "* " if i == r.chosen else ""
            rows.append([str(i) + ("" if i in r.pareto else " (off front)"), mark + short(s),
                         f"{r.objective_value(i):.3f}", f"{s.error_small:+.0%}",
                         f"{s.d_pi2:+.0%}", f"{s.d_pi3:+.0%}", f"{s.print_time_s / 60:.0f}",
                         f"{s.safety_factor:.2f}"])
        obj = "mismatch" if r.objective == "deformation" else "law error"
        c.print(table(f"1:{r.scale:g}: Pareto set ({len(r.pareto)} of {len(sc)} candidates, "
                      f"the {len(shown)} lowest {obj} shown; * chosen)",
                      ["#", "net (material beads x layers, mesh, border)", obj,
                       "k small strain", "dPi2", "dPi3", "print min", "SF"], rows))
        c.print(table(f"1:{r.scale:g}: per material (on target: +-30 % at SF >= 1.5)",
                      ["material", "printable", "on target", "best net", "k", "SF",
                       "first on target", "k", "SF"],
                      [_material_row(row) for row in
                       result.record["scales"][f"{r.scale:g}"]["per_material"]]))
        for line in r.reasons:
            c.print(f"- {line}")
    if len(result.results) > 1:
        for row in result.record["reachable"]:
            rng = row["scale_range"]
            c.print(f"- {row['material'].upper()}: "
                    + (f"on target at 1:{', 1:'.join(f'{s:g}' for s in row['scales_on_target'])}"
                       f" (lambda {rng[0]:g}-{rng[1]:g} of the series)" if rng else
                       "on target at none of the scales"))
        c.print(table("Scale series: the best net at each scale",
                      ["scale", "net", "k small strain", "mismatch", "select's", "dPi2", "dPi3",
                       "binding"], [_series_row(row) for row in result.record["series"]]))
    c.print(f"ran on {result.where}; {len(files)} files in {out}/ "
            f"(design.json -> printgen make --design; printgen testpieces: coupons and a "
            "panel to test first)")
    sys.stdout.flush()


def shown_rows(r: SearchResult) -> list[int]:
    """The candidates of the Pareto table: the chosen net first (also when the datasheet
    penalty of its ranking keeps it off the front), then the front's lowest objective values,
    `SHOW` in all."""
    front = sorted((i for i in r.pareto if i != r.chosen),
                   key=lambda i: (r.objective_value(i), i))
    first = [] if r.chosen is None else [r.chosen]
    return (first + front)[:SHOW]


def _material_row(row: dict) -> list[str]:
    def net(c: dict | None) -> list[str]:
        if c is None:
            return ["none", "-", "-"]
        return [f"{c['beads_across']}x{c['layers']}, {c['mesh_x_mm']:.3g}x{c['mesh_y_mm']:.3g} mm",
                f"{c['error_small_strain']:+.0%}", f"{c['safety_factor']:.1f}"]

    name = row["material"].upper() + (" (datasheet)" if row["datasheet"] else "")
    return [name, str(row["feasible"]), str(row["on_target"]), *net(row["best"]),
            *net(row["first_on_target"])]


def _series_row(row: dict) -> list[str]:
    if row["chosen"] is None:
        return [f"1:{row['scale']:g}", "none", "-", "-", "-", "-", "-",
                "; ".join(row["binding_constraints"])]
    ch = row["chosen"]

    def f(v: float | None) -> str:
        return "-" if v is None else f"{v:.3f}"

    return [f"1:{row['scale']:g}", (f"{ch['material'].upper()} {ch['beads_across']}x"
                                    f"{ch['layers']}, {ch['mesh_x_mm']:.3g}x"
                                    f"{ch['mesh_y_mm']:.3g} mm"),
            f"{row['error_small_strain']:+.0%}", f(row["mismatch_rms"]),
            f(row["select_mismatch_rms"]), f"{row['d_pi2']:+.0%}", f"{row['d_pi3']:+.0%}",
            "; ".join(row["binding_constraints"]) or "-"]
