"""`printgen testpieces DESIGN [--orientation short|long] [--out DIR] [--force] [--json]`: the
tensile coupons and the net test panel (a diamond's or a square's) to print and test before the
barrier, and for a design with waved strands the waved-strand coupon and its predicted curve
(printgen.run.testpieces), written atomically into DIR (default `out/<design>-testpieces`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from printgen.commands.common import add_json_arg, console, emit_json, run_options, table


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("testpieces", help="tensile coupons of the net strand and a net test "
                                          "panel to print, test and calibrate first")
    p.add_argument("design", type=Path, help="a design.json (printgen design or make)")
    p.add_argument("--orientation", choices=("short", "long"), default="short",
                   help="panel: mesh diagonal along the load (default short, as the paper's "
                        "panels); a square net's panel is pulled along its strands either way")
    p.add_argument("--out", "-o", type=Path, help="output directory")
    p.add_argument("--force", action="store_true",
                   help="replace --out even when it holds files printgen did not write")
    add_json_arg(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from printgen.run import api

    out = args.out or Path("out") / f"{args.design.stem}-testpieces"
    rec = api.testpieces(args.design, out, orientation=args.orientation,
                         options=run_options(args))
    if args.json:
        emit_json(rec)
        return 0
    c = console()
    if rec["material_source"] == "datasheet":
        c.print(f"[bold yellow]{rec['material']} rests on datasheet values[/]: print the test "
                "pieces below and calibrate before printing the barrier")
    cg, pg = rec["coupon"]["geometry"], rec["panel"]["geometry"]
    rows = [["coupon", (f"{cg['width_mm']:.4g} x {cg['thickness_mm']:.4g} mm strip, gauge "
             f"{cg['gauge_length_mm']:.4g} mm, eyelet tabs {cg['eyelet_outer_mm']:.4g} mm on "
             f"{cg['pin_hole_mm']:.4g} mm pins {cg['pin_distance_mm']:.4g} mm apart (print "
             f"{cg['count']})"), f"{rec['coupon']['readback_vs_stl']:+.1%}"],
            ["panel", (f"{pg['printed_mm'][0]:.4g} x {pg['printed_mm'][1]:.4g} mm, clamps "
             f"{pg['width_mm']:.4g} mm wide, {pg['length_mm']:.4g} mm apart, "
             f"{pg['clamp_depth_mm']:.4g} mm held each end"),
             f"{rec['panel']['readback_vs_stl']:+.1%}"]]
    w = rec.get("wave_coupon")
    if w is not None:
        g, e = w["geometry"], w["expected_curve"]
        rows.append(["wave-coupon", (
            f"{g['strands']} waved strands ({g['amplitude_mm']:g} mm, {g['half_waves']} "
            f"half-wave(s)) over a {g['chord_mm']:.4g} mm chord between {g['tab_mm']:g} mm "
            f"tabs; predicted knee {e['knee_strain']:.1%} at {e['force_at_knee_n']:.3g} N"),
            f"{w['readback_vs_stl']:+.1%}"])
    c.print(table(f"test pieces in {out}", ["piece", "geometry", "G-code vs STL"], rows))
    if w is not None:
        c.print(w["print_first"])
    for line in rec["loop"]:
        c.print(line)
    return 0
