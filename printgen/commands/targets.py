"""`printgen targets`: the model's similitude targets, Pi groups and flow check."""

from __future__ import annotations

import argparse

from rich.markup import escape

from printgen.commands.common import (
    add_json_arg,
    add_prototype_args,
    console,
    emit_json,
    fmt,
    table,
)
from printgen.run import api
from printgen.scaling.similitude import ScaledTargets


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("targets", help="similitude targets of the model at 1/lambda")
    add_prototype_args(p)
    add_json_arg(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    t = api.targets(args.prototype, args.scale)
    if args.json:
        emit_json(t.to_record())
        return 0
    show_targets(t.prototype, t)
    return 0


def show_targets(name: str, t: ScaledTargets) -> None:
    out = console()
    rows = [[r.label, r.unit, f"{r.exponent:g}", fmt(r.prototype), fmt(r.model)] for r in t.rows]
    out.print(table(f"{name}: targets at 1:{t.scale:g} (model = prototype x lambda^exponent)",
                    ["quantity", "unit", "exp", "prototype", "model"], rows))
    pis = [[k, fmt(t.pi_prototype[k]), fmt(t.pi_model[k])] for k in t.pi_prototype]
    out.print(table("Pi groups", ["group", "prototype", "model"], pis))
    f = t.flow
    out.print(f"Model flow: v = {f.velocity:.3g} m/s, h = {f.depth * 1e3:.3g} mm, "
              f"Fr = {f.froude:.2f}, Re = {f.reynolds:.0f} (R_h = {f.hydraulic_radius * 1e3:.3g} "
              f"mm), Q = {f.discharge * 1e3:.3g} L/s over {f.channel_width * 1e3:.0f} mm")
    show_warnings(t)


def show_warnings(t: ScaledTargets) -> None:
    """The targets' warnings (model flow, the flume's limits, the printed mesh), and what
    clears the flume's limits."""
    out = console()
    for w in t.warnings:
        out.print(f"[bold yellow]warning:[/] {escape(w)}")
    if t.flow.fix:
        out.print(f"[bold]Flume:[/] {escape(t.flow.fix)}")
