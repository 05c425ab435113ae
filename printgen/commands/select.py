"""`printgen select`: ranked material x pass layouts for the cables and the net."""

from __future__ import annotations

import argparse

from printgen.commands.common import (
    add_json_arg,
    add_prototype_args,
    check_profile_args,
    console,
    emit_json,
    fmt,
    table,
)
from printgen.commands.targets import show_warnings
from printgen.inputs.prototype import load_prototype
from printgen.run import api
from printgen.scaling.selection import Candidate, Selection

SHOW = 8  # candidates shown per component in the table (all are in --json)
STIFFNESS_WARN = 0.25  # |stiffness error| of the choice beyond which select warns


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("select", help="rank polymers and pass layouts against the targets")
    add_prototype_args(p)
    p.add_argument("--printer", help="printer profile (default: the prototype's [model] choice)")
    p.add_argument("--materials", nargs="+", metavar="NAME",
                   help="material profiles to consider (default: all)")
    p.add_argument("--all", action="store_true", help="show every candidate, not the best 8")
    add_json_arg(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    check_profile_args(args, "printer", "materials")
    proto = load_prototype(args.prototype)
    t = api.targets(proto, args.scale)
    s = api.select(proto, args.scale, printer=args.printer, materials=args.materials)
    if args.json:
        emit_json({"prototype": proto.name, "scale": args.scale, **s.to_record(),
                   "warnings": list(t.warnings)})
        return 0
    show_selection(s, None if args.all else SHOW)
    show_bed(proto, args.scale, s)
    show_warnings(t)  # the targets' (flume, printed mesh): they hold for any choice above
    return 0


def show_bed(proto, scale: float, s: Selection) -> None:
    """Whether the chosen net fits the printer's bed (and which printers or lambda fit)."""
    from printgen.errors import DesignError
    from printgen.scaling.bedfit import bed_fit
    from printgen.scaling.plan import make_design
    from printgen.scaling.similitude import scale_targets

    try:
        fit = bed_fit(make_design(proto, scale_targets(proto, scale), s))
    except DesignError as exc:
        console().print(f"[bold red]No design:[/] {exc}")
        return
    console().print(fit.message() if fit.ok else f"[bold red]{fit.message()}[/]")


def show_selection(s: Selection, limit: int | None) -> None:
    out = console()
    for what, cands, why, unit in (("cables", s.cables, s.cable_rationale, "E*A N"),
                                   ("net", s.net, s.net_rationale, "N/m")):
        if not cands:
            continue
        rows = [_row(i + 1, c) for i, c in enumerate(cands[:limit])]
        stiff = f"stiffness {unit}" + (" across / up" if what == "net" else "")
        cols = ["#", "material", "E source", "section mm", "passes", stiff,
                "error", "Pi3", "SF", "score", "printable"]
        name = f"{what} ({s.net_mesh})" if what == "net" and s.net_mesh else what
        target = (f"{cands[0].target_across:.4g} across, {cands[0].target_up:.4g} up"
                  if cands[0].target_across is not None else f"{cands[0].target:.4g}")
        out.print(table(f"{name}: target {target} {unit} "
                        f"({len(cands)} candidates, best first)", cols, rows))
        best = cands[0]
        if best.feasible and abs(best.error) > STIFFNESS_WARN:
            out.print(f"[bold red]Warning:[/] the best {what} candidate is "
                      f"{best.direction_text() or f'{best.error:+.0%}'} off its stiffness "
                      "target: the model will not deform like the prototype; printgen design "
                      "searches mesh and strand too.")
        out.print(f"[bold]Choice:[/] {why}\n")


def _row(rank: int, c: Candidate) -> list[str]:
    s = c.section
    err = f"{c.error:+.1%}"
    if c.component == "net":  # both barrier directions, never one number
        err = f"{c.direction_text()} (rms {c.error_rms:.2f})"
    source = "panel law" if "panel law" in c.modulus_source else c.modulus_source.split()[0]
    return [str(rank), c.material_name, source, f"{s.width_mm:g} x {s.thickness_mm:g}",
            str(s.passes), fmt(c.stiffness) if c.stiffness_across is None else
            f"{fmt(c.stiffness_across)} / {fmt(c.stiffness_up)}", err, f"{c.pi3_deviation:+.0%}",
            f"{c.safety_factor:.1f}", f"{c.score:.3f}", "yes" if c.feasible else "NO: "
            + c.reasons[0][:48]]
