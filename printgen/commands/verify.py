"""`printgen verify PROTOTYPE --scale 40 --design OUT/design.json [--measured FILE.csv]
[--fit stiffness|slack] [--out DIR]`: the pre-print check of an existing design with its
uncertainty band; with a lab's measured loading test, the mismatch and one fitted factor."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from printgen.commands.common import (
    add_json_arg,
    add_load_args,
    add_prototype_args,
    add_time_limit_arg,
    console,
    emit_json,
    incomplete_code,
    run_options,
    spinner,
    table,
)
from printgen.verification.measured import COLUMNS, FIT_KINDS, LEVEL_COLUMN


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("verify", help="re-run the pre-print check of a design (design.json) "
                                      "with its uncertainty band; compare a measured test")
    add_prototype_args(p)
    p.add_argument("--design", type=Path, required=True,
                   help="the design.json that printgen make wrote")
    p.add_argument("--measured", type=Path, metavar="FILE.csv",
                   help=f"a loading test (',' or ';'): {LEVEL_COLUMN} and any of "
                        f"{', '.join(COLUMNS)}")
    p.add_argument("--fit", choices=FIT_KINDS, default="stiffness",
                   help="the one factor of the printed net fitted to --measured "
                        "(default: its effective stiffness)")
    p.add_argument("--out", "-o", type=Path,
                   help="output folder (default: beside the design's folder, '<name>-verify')")
    add_load_args(p, "check")
    p.add_argument("--force", action="store_true",
                   help="replace an output folder printgen did not write")
    add_time_limit_arg(p)
    add_json_arg(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from printgen.run import api
    from printgen.run.verify import band_summary, fitted_name

    folder = args.design.resolve().parent
    out = args.out or folder.with_name(f"{folder.name}-verify")
    t0 = time.perf_counter()
    with spinner("reading inputs") as status:  # no thread: the fit's workers fork with its imports
        res = api.verify_design(args.prototype, args.scale, args.design, out,
                                measured=args.measured, fit=args.fit, options=run_options(args),
                                progress=lambda s: status.update(f"{s} ..."))
    if args.json:
        emit_json(res.record)
        return incomplete_code(res.record, "verify")
    c = console()
    v = res.record["verification"]
    c.print(f"[bold]{v['verdict']}[/bold]: {v['summary']}")
    rows = [[line.split(": ", 1)[0], line.split(": ", 1)[1]] for line in band_summary(res)]
    c.print(table(f"printgen verify: 1:{res.design.scale:g} in {time.perf_counter() - t0:.1f} s"
                  " (prototype vs the model's band)", ["quantity", "verdict"], rows))
    if res.fit is not None:
        c.print(res.record["measured"]["fit"]["sentence"])
        if res.profile_text:
            from printgen.inputs.profiles import user_folder_hint

            name = fitted_name(res.design)
            c.print(f"Feed it back: {out / name} is the fitted profile; "
                    f"{user_folder_hint('materials', name)}, and use it as the net's material.")
        elif res.fit.kind != "multi":
            c.print("No profile to feed back: look for the cause in the test (sensor zero, "
                    "mounting, slack) before changing the material.")
    c.print(f"{len(res.files)} files in {out}/ ; open {out / 'report.html'}")
    sys.stdout.flush()
    return incomplete_code(res.record, "verify")
