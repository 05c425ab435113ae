"""`printgen calibrate`: material profiles from tensile-test exports.

    printgen calibrate FILE|DIR... --material petg-lab [--kind cable|dogbone|panel]
        [--width-mm W --thickness-mm T | --area-mm2 A] [--gauge-length-mm L]
        [--grip-distance-mm L] [--specimen SIDECAR.toml] [--column ROLE=NAME] [--unit ROLE=UNIT]
        [--window 0.05,0.25 | --window auto] [--preload N [--zero interpolate|first]]
        [--secant 0.5,1] [--flag COLUMN=active-low|active-high|ignore] [--keep-flagged]
        [--strain-source auto|extensometer|crosshead]
        [--machine-stiffness N_PER_MM | --compliance-curve FILE]
        [--strength-only] [--save [--out DIR] [--inherits petg]] [--plot DIR] [--json]
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from rich.console import Console
from rich.markup import escape
from rich.measure import Measurement
from rich.table import Table

from printgen.calibrate.aggregate import MIN_SAMPLES
from printgen.calibrate.compliance import from_curve, from_stiffness
from printgen.calibrate.fit import DEFAULT_ZERO, ISO_WINDOW, ZERO_MODES
from printgen.calibrate.pipeline import Calibration
from printgen.calibrate.record import calibration_record, units
from printgen.calibrate.sample import DEFAULT_SECANTS, PRELOAD_STEPS, FitOptions, SampleFit
from printgen.calibrate.specimen import KINDS
from printgen.calibrate.windows import MACHINE_TOL, machine_refutes
from printgen.commands.common import add_json_arg, console, emit_json, fmt, table
from printgen.errors import CalibrationError
from printgen.inputs.profiles import profile_name
from printgen.run import api

WIDEST = 10_000  # characters: a results table's width is measured up to this
PRELOAD_COL = "ΔE % at P∓10%"  # modulus change (%) at 0.9 and 1.1 x the preload
DIMENSION_OPTIONS = (("width_mm", "width", 1e-3), ("thickness_mm", "thickness", 1e-3),
                     ("area_mm2", "area", 1e-6), ("gauge_length_mm", "gauge_length", 1e-3),
                     ("grip_distance_mm", "grip_distance", 1e-3))


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("calibrate", help="fit moduli, strength and panel laws from tensile tests")
    p.add_argument("files", nargs="+", help="tensile-test exports (.csv .txt .tsv .dat in any "
                   "case, or a zip of one) or directories (every export in them; sidecar "
                   ".toml files are never read as data)")
    p.add_argument("--material", required=True, help="profile name to write (e.g. petg-lab)")
    p.add_argument("--kind", choices=KINDS, help="specimen type (default: sidecar, else cable)")
    for opt, _, _ in DIMENSION_OPTIONS:
        p.add_argument("--" + opt.replace("_", "-"), type=float, dest=opt, metavar="X",
                       help=f"specimen {opt.rsplit('_', 1)[0].replace('_', ' ')} "
                            f"({opt.rsplit('_', 1)[1]}), when the file does not give it")
    p.add_argument("--specimen", metavar="TOML", help="specimen sidecar (default: <file>.toml "
                   "or specimen.toml beside each export); a waved test piece's (kind waved, "
                   "from printgen testpieces) fits the exports against the beam model of its "
                   "strands: the material law's scale, the knee and slopes compared")
    p.add_argument("--column", action="append", default=[], metavar="ROLE=NAME",
                   help="choose a column by header name or 1-based index; roles: time, force, "
                        "displacement, strain, stress")
    p.add_argument("--unit", action="append", default=[], metavar="ROLE=UNIT",
                   help="unit of a column when the file does not say (e.g. force=kN)")
    p.add_argument("--delimiter", choices=[",", ";", "tab"], help="override detection")
    p.add_argument("--decimal", choices=[".", ","], help="override detection")
    p.add_argument("--window", default=None, metavar="LO,HI|auto",
                   help="modulus strain window in %% (default 0.05,0.25 as ISO 527-1), or 'auto' "
                        "for the steepest window as test-machine software does")
    p.add_argument("--auto-span", type=float, default=FitOptions.auto_span,
                   help="auto window: fraction of the rise to the peak it spans (default 0.15)")
    p.add_argument("--preload", type=float, metavar="N", help="zero strain at this force (N); "
                   "the modulus at -10 %% and +10 %% of it is shown too")
    p.add_argument("--zero", choices=ZERO_MODES, help=f"preload zero (default {DEFAULT_ZERO}): "
                   "'interpolate' between the samples around the preload, or 'first' sample at "
                   "or above it (as many testers' software does)")
    p.add_argument("--flag", action="append", default=[], metavar="COLUMN=CONVENTION",
                   help="how a status column reads: active-low (0 = set, e.g. an end stop with "
                        "a pull-up), active-high (1 = set) or ignore (default: from the data: "
                        "a column constant through the test marks nothing, one that changes "
                        "marks the rows that differ from its start)")
    p.add_argument("--keep-flagged", action="store_true",
                   help="keep samples a tester flag column marks (step loss, end stop, ...) in "
                        "the statistics (default: reported and left out)")
    p.add_argument("--secant", default=",".join(f"{e * 100:g}" for e in DEFAULT_SECANTS),
                   metavar="E1,E2", help="strains (%%) for secant moduli (default 0.5,1)")
    p.add_argument("--strain-source", choices=("auto", "extensometer", "crosshead"),
                   default="auto", help="strain channel (auto: extensometer when present)")
    comp = p.add_mutually_exclusive_group()
    comp.add_argument("--machine-stiffness", type=float, metavar="N_PER_MM",
                      help="constant machine stiffness for the compliance correction")
    comp.add_argument("--compliance-curve", metavar="FILE",
                      help="force-displacement export of a rigid-bar test (system compliance)")
    p.add_argument("--strength-only", action="store_true",
                   help="force-only files: strength = peak force / cross-section, no modulus")
    p.add_argument("--conditions", default="", help="test conditions to record in the profile")
    p.add_argument("--save", action="store_true",
                   help="write DIR/materials/<material>.toml (DIR: --out or $PRINTGEN_PROFILES)")
    p.add_argument("--out", metavar="DIR", help="profile root to write into (implies --save)")
    p.add_argument("--inherits", metavar="NAME",
                   help="bundled profile the new one inherits (datasheet, print settings)")
    p.add_argument("--date", help="test date to record (default: today, ISO format)")
    p.add_argument("--plot", metavar="DIR", help="write DIR/<material>.png")
    add_json_arg(p)
    p.set_defaults(func=run)


def options_from(args: argparse.Namespace) -> FitOptions:
    """FitOptions from the command line."""
    if args.window is None:
        window: tuple[float, float] | None = ISO_WINDOW
    elif args.window.strip().lower() == "auto":
        window = None
    else:
        lo, hi = _floats(args.window, "--window", 2)
        window = (lo / 100, hi / 100)
    compliance = None
    if args.machine_stiffness is not None:
        compliance = from_stiffness(args.machine_stiffness)
    elif args.compliance_curve is not None:
        compliance = from_curve(args.compliance_curve)
    if not 0 < args.auto_span < 1:
        raise CalibrationError(f"--auto-span {args.auto_span:g} must be between 0 and 1")
    if args.zero is not None and args.preload is None:
        raise CalibrationError(f"--zero {args.zero} needs --preload N: without a preload, strain "
                               "is zeroed at the first sample")
    return FitOptions(window=window, auto_span=args.auto_span, preload=args.preload,
                      secant_strains=tuple(e / 100 for e in _floats(args.secant, "--secant")),
                      strain_source=args.strain_source, compliance=compliance,
                      zero=args.zero or DEFAULT_ZERO, keep_flagged=args.keep_flagged)


def run(args: argparse.Namespace) -> int:
    material = profile_name(args.material, "--material")  # names <material>.toml and .png
    if args.inherits is not None:
        profile_name(args.inherits, "--inherits")
    if args.date is not None:  # before any work: a bad date must not cost the fit
        from printgen.calibrate.profile_writer import tested_on

        tested_on(args.date)
    for opt, _, _ in DIMENSION_OPTIONS:  # a zero width would divide by zero deep in the fit
        value = getattr(args, opt)
        if value is not None and not (math.isfinite(value) and value > 0):
            unit = opt.rsplit("_", 1)[1]
            raise CalibrationError(f"--{opt.replace('_', '-')} {value:g}: a specimen dimension "
                                   f"must be a positive number of {unit}; give the measured "
                                   "value, or leave it out when the file gives it")
    spec = {name: getattr(args, opt) * f for opt, name, f in DIMENSION_OPTIONS
            if getattr(args, opt) is not None}
    if args.kind:
        spec["kind"] = args.kind
    cal = api.calibrate(
        args.files, material=args.material, options=options_from(args), specimen=spec,
        specimen_file=args.specimen, columns=_pairs(args.column, "--column"),
        units=_pairs(args.unit, "--unit"),
        delimiter="\t" if args.delimiter == "tab" else args.delimiter, decimal=args.decimal,
        strength_only=args.strength_only, conditions=args.conditions,
        flags=_pairs(args.flag, "--flag", "endstop=active-low"))
    if not isinstance(cal, Calibration):
        return _waved(cal, args)
    written = {}
    if args.save or args.out:
        from printgen.calibrate.profile_writer import value_sources, write_profile

        refuted = machine_refutes(cal.samples) if args.window is None else None
        if refuted:  # the default window against the machine in every file: ask, not guess
            raise CalibrationError(
                f"the fitted modulus differs from the machine's own by more than "
                f"{MACHINE_TOL:.0%} in {refuted[0]} of {refuted[1]} files with the default ISO "
                "window (0.05-0.25 %): no profile written; choose the window: --window auto "
                "(the steepest part, as the machine's software fits it) or --window 0.05,0.25 "
                "to keep the ISO value")

        path, mat = write_profile(cal, name=args.material, out=args.out, inherits=args.inherits,
                                  date=args.date)
        written = {"profile": str(path), **value_sources(cal, path, mat)}
        if cal.kind == "panel" and mat.panel_law is not None:
            written["panel_law_kappa_kn_per_m_per_m"] = [k / 1e3 for k in mat.panel_law.kappas]
            written["panel_law_knee_strain_percent"] = [k * 100 for k in
                                                        mat.panel_law.knee_strains]
    if args.plot:
        from printgen.calibrate.plot import plot_calibration

        written["plot"] = str(plot_calibration(cal, Path(args.plot) / f"{material}.png"))
    if args.json:
        emit_json({**calibration_record(cal), "written": written})
        return 0
    show(cal, written)
    return 0


def _piece(model) -> str:
    """What a law-scale fit's sidecar describes, as its errors name it."""
    if model.straight:
        return "test panel"
    return "waved test panel" if model.panel else "waved coupon"


def _waved(cal, args: argparse.Namespace) -> int:
    """Save, plot and show a waved-coupon calibration (`printgen.calibrate.waved`)."""
    written: dict[str, object] = {}
    if args.save or args.out:
        from printgen.calibrate.profile_writer import write_profile

        if args.inherits is not None and args.inherits.lower() != cal.model.material.lower():
            raise CalibrationError(
                f"--inherits {args.inherits}: the {_piece(cal.model)}'s fit scales "
                f"{cal.model.material}'s law (the law its prediction assumed); give --inherits "
                f"{cal.model.material}")
        path, mat = write_profile(cal, name=args.material, out=args.out,
                                  inherits=args.inherits, date=args.date)
        written["profile"] = str(path)
        written["wrote"] = ", ".join(f"[measured.{k}]" for k in
                                     measured_keys(cal, args.date))
    if args.plot:
        from printgen.calibrate.plot import plot_waved

        written["plot"] = str(plot_waved(cal, Path(args.plot) / f"{cal.material}.png"))
    if args.json:
        emit_json({**cal.to_record(), "written": written})
        return 0
    out = console()
    out.print(escape(cal.summary().text()))
    for k, v in written.items():
        out.print(escape(f"{k}: {v}"))
    return 0


def measured_keys(cal, date: str | None) -> list[str]:
    from printgen.calibrate.profile_writer import measured_tables

    return list(measured_tables(cal, date=date))


def show(cal: Calibration, written: dict) -> None:
    out = console()
    _, mf, su, sf = units(cal)
    panel = cal.kind == "panel"
    mu = "kN/m/m" if panel else "GPa"  # panels: kappa = slope of F/w over strain / length
    if panel and cal.samples:
        mf = 1e3 * cal.samples[0].specimen.strain_length()
    if cal.samples:
        cols = ["file", f"{'kappa' if panel else 'E'} {mu}", PRELOAD_COL, "window %", "r2",
                f"{'k1/k2' if panel else 'E1/E2'} {mu}", "knee %",
                *[f"sec {e * 100:g}%" for e in cal.options.secant_strains],
                f"max {su}", "break %", f"machine {mu}", "diff", "flags"]
        rows = [[escape(c) for c in _sample_row(s, cal, mf, sf)] for s in cal.samples]
        cols, rows = _drop_empty(cols, rows, (PRELOAD_COL, f"machine {mu}", "diff", "flags"))
        _print_whole(out, table(escape(f"{cal.material}: {cal.kind} specimens, strain from "
                                       f"{'; '.join(cal.strain_sources)}{_zero_text(cal)}"),
                                cols, rows))
    elif cal.strength_samples:
        rows = [[escape(Path(s.path).name), f"{s.peak_force:.2f}",
                 fmt(None if s.strength is None else s.strength / sf),
                 escape(_flag_text(s, cal))] for s in cal.strength_samples]
        _print_whole(out, table(escape(f"{cal.material}: strength only (force-only files)"),
                                ["file", "peak N", f"strength {su}", "flags"], rows))
    for what, st, f, u in (("kappa (window)" if panel else "modulus", cal.modulus, mf, mu),
                           ("strength", cal.strength, sf, su),
                           ("elongation at break", cal.elongation, 1e-2, "%")):
        if st is not None:
            sd = "-" if st.sd is None else f"{st.sd / f:.4g}"
            n = f"n = {st.n}" + (": spread only" if st.n < MIN_SAMPLES else "")
            extra = _preload_text(cal) if st is cal.modulus else ""
            out.print(f"[bold]{what}[/]: {st.mean / f:.4g} ± {sd} {u} ({n}){extra}")
            if st is cal.modulus and cal.window_summary:
                out.print(escape(f"  {cal.window_summary}"))
    if cal.panel is not None:
        p = cal.panel
        out.print(f"[bold]panel law[/]: kappa {p.kappa1.mean / 1e3:.4g} kN/m/m up to "
                  f"{p.knee.mean * 100:.3g} % strain, then {p.kappa2.mean / 1e3:.4g} kN/m/m "
                  f"(panel {p.panel_length * 1e3:g} mm long, n = {p.kappa1.n})")
    for w in cal.warnings:
        out.print(f"[yellow]warning:[/] {escape(w)}")
    for k, v in written.items():
        out.print(escape(f"{k}: {v}"))


def _sample_row(s: SampleFit, cal: Calibration, mf: float, sf: float) -> list[str]:
    b, m = s.bilinear, s.machine_modulus
    return [Path(s.path).name, fmt(s.modulus / mf), _change_text(s.preload_change),
            f"{s.linear.lo * 100:.3g}-{s.linear.hi * 100:.3g}", f"{s.linear.r2:.4f}",
            "-" if b is None else f"{b.slope1 / mf:.4g}/{b.slope2 / mf:.4g}",
            "-" if b is None else f"{b.knee * 100:.3g}",
            *[fmt(None if v is None else v / mf) for v in s.secants.values()],
            fmt(None if s.strength is None else s.strength / sf),
            fmt(None if s.elongation_at_break is None else s.elongation_at_break * 100),
            fmt(None if m is None else m / mf),
            "-" if m is None else f"{s.modulus / m - 1:+.1%}", _flag_text(s, cal)]


def _print_whole(out: Console, t: Table) -> None:
    """Print a results table whole: file names (specimens must be told apart) and numbers are
    never cut short; the console widens to the table (a narrow terminal wraps its lines)."""
    out.width = max(out.width, Measurement.get(out, out.options.update_width(WIDEST), t).maximum)
    out.print(t)


def _drop_empty(cols: list[str], rows: list[list[str]], optional: tuple[str, ...]
                ) -> tuple[list[str], list[list[str]]]:
    """Leave out the `optional` columns that are '-' in every row (the table stays narrow)."""
    keep = [j for j, c in enumerate(cols) if c not in optional or any(r[j] != "-" for r in rows)]
    return [cols[j] for j in keep], [[r[j] for j in keep] for r in rows]


def _flag_text(s, cal: Calibration) -> str:
    """Flag column names set in a sample, and whether it left the statistics."""
    if not s.flags:
        return "-"
    names = ", ".join(f.split(" set at ")[0] for f in s.flags)
    return f"{names}: {'out' if s.path in cal.excluded else 'kept'}"


def _change_text(change: tuple[float | None, ...] | None) -> str:
    """'-1.2/+0.8': modulus change (%) at -10 % and +10 % preload; '-' without a preload."""
    if change is None:
        return "-"
    return "/".join("?" if c is None else f"{c * 100:+.1f}" for c in change)


def _zero_text(cal: Calibration) -> str:
    o = cal.options
    if o.preload is None:
        return "; zero at the first sample (no preload)"
    return f"; zero at preload {o.preload:g} N ({o.zero})"


def _preload_text(cal: Calibration) -> str:
    if cal.preload_change is None or cal.options.preload is None:
        return ""
    lo, hi = (f * cal.options.preload for f in PRELOAD_STEPS)
    return (f"; preload {lo:g} / {hi:g} N (±10 %) moves it {_change_text(cal.preload_change)} "
            f"% (zero: {cal.options.zero})")


def _floats(text: str, opt: str, n: int | None = None) -> list[float]:
    try:
        vals = [float(v) for v in text.split(",") if v.strip()]
    except ValueError as exc:
        raise CalibrationError(f"{opt} {text!r}: expected comma-separated numbers") from exc
    if n is not None and len(vals) != n:
        raise CalibrationError(f"{opt} {text!r}: expected {n} numbers (e.g. 0.05,0.25)")
    return vals


def _pairs(items: list[str], opt: str, example: str = "force=Kraft") -> dict[str, str]:
    out = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip() or not value.strip():
            raise CalibrationError(f"{opt} {item!r}: expected NAME=VALUE, e.g. {example}")
        out[key.strip().lower()] = value.strip()
    return out
