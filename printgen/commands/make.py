"""`printgen make PROTOTYPE --scale 40 [--printer NAME] [--out DIR] [--json]`: everything a lab
needs, written atomically into DIR (default `out/<prototype>-1-<lambda>`)."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from rich.markup import escape

from printgen.commands.common import (
    add_json_arg,
    add_load_args,
    add_prototype_args,
    check_profile_args,
    console,
    emit_json,
    incomplete_code,
    run_options,
    seconds,
    spinner,
    table,
)
from printgen.report.pdf import PAPERS
from printgen.run import api
from printgen.run.budget import DEFAULT_LIMIT_S
from printgen.run.make import json_output

EXIT_TIME_LIMIT = 4  # stopped at --time-limit (printgen.cli maps TimeLimitError to it)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("make", help="targets, selection, parts, slicer profiles, G-code, "
                                    "verification and report in one run")
    add_prototype_args(p)
    p.add_argument("--printer", help="printer profile (default: the prototype's [model] choice)")
    p.add_argument("--out", "-o", type=Path, help="output directory")
    add_load_args(p, "verify", several=True)
    p.add_argument("--step", action="store_true", help="also write STEP files (needs cadquery)")
    p.add_argument("--design", metavar="FILE", type=Path,
                   help="print this design.json (from printgen design) instead of select's")
    p.add_argument("--time-limit", type=seconds, default=None, metavar="SECONDS",
                   help=f"refuse runs estimated longer than this and stop the run (exit "
                        f"{EXIT_TIME_LIMIT}, nothing written) once it has run this long "
                        f"(default: refuse over {DEFAULT_LIMIT_S:g} s, about a minute on 2 "
                        f"cores, and never stop)")
    p.add_argument("--force", action="store_true",
                   help="replace --out even when it holds files printgen did not write")
    p.add_argument("--pdf", action="store_true",
                   help="also print report.pdf with a headless Chrome, Edge or Chromium "
                        "(skipped, with one line, when none is installed)")
    p.add_argument("--paper", choices=sorted(PAPERS), default=None,
                   help="report.pdf's page size (default: a4)")
    add_json_arg(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    check_profile_args(args, "printer")
    out = args.out or Path("out") / f"{Path(args.prototype).stem}-1-{args.scale:g}"
    t0 = time.perf_counter()
    options = run_options(args)
    with spinner("planning") as status:  # no thread: make's helper forks with its imports
        ctx = api.make(args.prototype, args.scale, out, options=options,
                       progress=Progress(status))
    seconds = time.perf_counter() - t0
    if args.json:
        emit_json(json_output(ctx))
    else:
        show_summary(ctx, out, seconds)
    return incomplete_code(ctx.record, "make")


class Progress:
    """The spinner's text: the current step (or the load-level bars of the verification) and,
    for a long run, its size estimate below it. Transient: a failed run still ends in one line,
    and the estimate is in report.json ("size") and in the summary."""

    def __init__(self, status) -> None:
        self.status, self.estimate = status, ""

    def __call__(self, label: str) -> None:
        if label.startswith("estimate:"):
            self.estimate = f"\n{label}"
            return
        self.status.update(f"{label} ...{self.estimate}")


def _net_error(ctx) -> str:
    """The printed net's small-strain stiffness error across and up the barrier: the design
    file's own net with --design, else the selection's choice."""
    own = ctx.record.get("design_net")
    if own:
        return f"{own['stiffness_error_across']:+.0%} across, {own['stiffness_error_up']:+.0%} up"
    return ctx.selection.net[0].direction_text()


def show_summary(ctx, out: Path, seconds: float) -> None:
    c = console()
    d = ctx.design
    rows = [["net", (f"{d.net.material.upper()} {d.net.strand.width_mm:g} x "
             f"{d.net.strand.thickness_mm:g} mm, {d.net.strand.passes} passes"),
             f"{_net_error(ctx)} (small strain)"]]
    if ctx.selection.cables:
        cab = ctx.selection.cables[0]
        rows.append(["cables", (f"{cab.material_name} {cab.section.width_mm:g} x "
                     f"{cab.section.thickness_mm:g} mm, {cab.section.passes} passes"),
                     f"{cab.error:+.1%} E*A"])
    size = ctx.record.get("size")
    if size:
        nets = ", ".join(f"{k} {v['nodes']:,}" for k, v in size["nets"].items()) or "no sweep"
        rows.append(["size", f"nodes: {nets}", f"{size['mesh_segments']:,} strand segments"])
    ver = ctx.record.get("verification")
    if ver:
        rows.append(["verification", ver["verdict"], ver["summary"]])
    c.print(table(f"printgen make: 1:{ctx.targets.scale:g} in {seconds:.1f} s",
                  ["item", "choice", "stiffness / result"], rows))
    from printgen.report.summary import summary_lines

    for line in summary_lines(ctx.record.get("summary") or {})[1:]:  # verdict: in the table
        c.print(escape(line))  # a warning names its table: "[model] mesh ..."
    if ctx.record.get("pdf_skipped"):
        c.print(ctx.record["pdf_skipped"])
    c.print(f"{len(ctx.record['files'])} files in {out}/ ; open {out / 'report.html'}")
    sys.stdout.flush()
