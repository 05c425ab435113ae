"""`printgen panel DESIGN [--orientation short|long] [--mode free|blocked] [--wave MM
[--half-waves N]] [--json]`: the simulated tensile test of a design's printed net panel
(printgen.run.panel), to compare with a printed test panel before printing the barrier;
with --wave, of its net printed with curved strands, beside the net law of their curves."""

from __future__ import annotations

import argparse
from pathlib import Path

from printgen.commands.common import add_json_arg, console, emit_json, table


def register(sub: argparse._SubParsersAction) -> None:
    from printgen.run.panel import MODES, ORIENTATIONS

    p = sub.add_parser("panel", help="simulate a design's net panel tensile test (print a "
                                     "test panel and compare before printing the barrier)")
    p.add_argument("design", type=Path, help="a design.json (printgen design or make)")
    p.add_argument("--orientation", choices=ORIENTATIONS, action="append",
                   help="mesh diagonal along the load (default: both)")
    p.add_argument("--mode", choices=MODES, default="free",
                   help="free between the clamps (printed panels, default) or transverse "
                        "displacement blocked")
    p.add_argument("--wave", type=float, metavar="MM",
                   help="print the net's strands as in-plane waves of this amplitude (mm) "
                        "between junctions; the strand law is the beam model's curve")
    p.add_argument("--half-waves", type=int, metavar="N",
                   help="half-waves of each strand between two junctions (with --wave; "
                        "default 1)")
    add_json_arg(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from printgen.run import api
    from printgen.run.panel import wave_of

    wave = wave_of(args.wave, args.half_waves)
    runs = api.panel(args.design, orientations=args.orientation, mode=args.mode, wave=wave)
    if args.json:
        emit_json([{"orientation": dp.orientation, "test": dp.test.describe(),
                    "strands": dp.strands or "straight",
                    "strand_law": {"knees": dp.law.knees, "slopes_n": dp.law.slopes},
                    "strain": dp.curve.strains, "force_per_width_n_per_m":
                    dp.curve.force_per_width, "measured_n_per_m": dp.measured,
                    "strand_curves_n_per_m": dp.expected,
                    "hold_share": dp.curve.hold_share} for dp in (r.panel for r in runs)])
        return 0
    c = console()
    for r in runs:
        dp = r.panel
        other = dp.measured if dp.expected is None else dp.expected
        rows = [[f"{e:.1%}", f"{n:.4g}", f"{k / 1e3:.3g}",
                 "" if other is None else f"{other[i]:.4g}"]
                for i, (e, n, k) in enumerate(zip(dp.curve.strains, dp.curve.force_per_width,
                                                  dp.curve.kappa, strict=True))]
        if dp.strands:
            c.print(dp.strands)
        c.print(table(f"panel test, {dp.orientation} diagonal: {dp.test.describe()}; meshes "
                      f"lie along the load at {r.lockup:.1%}",
                      ["strain", "force/width N/m", "kappa kN/m/m",
                       "profile N/m" if dp.expected is None else "strand curves N/m"], rows))
        if dp.curve.hold_share > 0.5:
            c.print(f"[bold yellow]the pin-jointed net is a mechanism here[/]: "
                    f"{dp.curve.hold_share:.0%} of the clamp force is the solver's hold, not "
                    "the strands; a printed panel's force comes from its rigid junctions")
    return 0
