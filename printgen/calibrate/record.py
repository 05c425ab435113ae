"""A calibration as plain data in file units (GPa, MPa, %, kN/m/m) for --json and tables."""

from __future__ import annotations

from typing import Any

from printgen.calibrate.aggregate import Stats
from printgen.calibrate.pipeline import Calibration
from printgen.calibrate.sample import PRELOAD_STEPS, SampleFit


def _pct(v: float | None) -> float | None:
    return None if v is None else v * 100


def preload_record(cal: Calibration, change: tuple[float | None, ...] | None,
                   moduli: tuple[float | None, ...] | None = None) -> dict[str, Any] | None:
    """Preloads at PRELOAD_STEPS x the preload, the modulus change there (%) and, for one
    sample, the moduli; None without a preload."""
    p = cal.options.preload
    if p is None or change is None:
        return None
    out: dict[str, Any] = {"preload_n": [p * f for f in PRELOAD_STEPS],
                           "change_percent": [_pct(c) for c in change]}
    if moduli is not None:
        mu, mf, _, _ = units(cal)
        out[f"modulus_{mu}"] = [None if m is None else m / mf for m in moduli]
    return out


def stats_record(s: Stats | None, factor: float) -> dict[str, Any] | None:
    """mean, sd, n, values divided by `factor`; outliers as indices."""
    if s is None:
        return None
    return {"mean": s.mean / factor, "sd": None if s.sd is None else s.sd / factor, "n": s.n,
            "values": [v / factor for v in s.values], "outliers": list(s.outliers)}


def units(cal: Calibration) -> tuple[str, float, str, float]:
    """(modulus unit, factor, strength unit, factor): GPa/MPa, or kN/m per unit strain and
    kN/m for panels (force per width)."""
    if cal.kind == "panel":
        return "kN/m", 1e3, "kN/m", 1e3
    return "GPa", 1e9, "MPa", 1e6


def sample_record(s: SampleFit, cal: Calibration) -> dict[str, Any]:
    mu, mf, su, sf = units(cal)
    b = s.bilinear
    rec: dict[str, Any] = {
        "file": s.path, "strain_source": s.strain_source,
        f"modulus_{mu}": s.modulus / mf, "window_percent": [s.linear.lo * 100, s.linear.hi * 100],
        "window_mode": s.linear.mode, "points": s.linear.n, "r2": s.linear.r2,
        "bilinear": None if b is None else {f"slope1_{mu}": b.slope1 / mf,
                                            f"slope2_{mu}": b.slope2 / mf,
                                            "knee_percent": b.knee * 100},
        "secant": {f"{e * 100:g}%": (None if v is None else v / mf) for e, v in s.secants.items()},
        "peak_force_n": s.peak_force, f"strength_{su}": None if s.strength is None
        else s.strength / sf,
        "specimen": {k: v for k, v in vars(s.specimen).items() if v is not None},
        "columns": s.columns, "elongation_at_break_percent": _pct(s.elongation_at_break),
        "preload_sensitivity": preload_record(cal, s.preload_change, s.preload_moduli),
        "flags": list(s.flags), "status_columns": s.status, "excluded": s.path in cal.excluded,
    }
    if s.window_check is not None:
        rec["window_check"] = s.window_check.record((mu, mf))
    if s.kappa is not None:
        rec["kappa_kn_per_m_per_m"] = s.kappa / 1e3
    if s.machine_modulus is not None:
        rec[f"machine_modulus_{mu}"] = s.machine_modulus / mf
        rec["difference_percent"] = (s.modulus / s.machine_modulus - 1) * 100
    return rec


def calibration_record(cal: Calibration) -> dict[str, Any]:
    """Everything the calibration found, in file units."""
    mu, mf, su, sf = units(cal)
    o = cal.options
    out: dict[str, Any] = {
        "material": cal.material, "kind": cal.kind,
        "options": {"window_percent": None if o.window is None else [w * 100 for w in o.window],
                    "auto_span": o.auto_span, "preload_n": o.preload,
                    "strain_source": o.strain_source, "zero": o.zero,
                    "keep_flagged": o.keep_flagged,
                    "compliance": None if o.compliance is None else o.compliance.describe()},
        "samples": [sample_record(s, cal) for s in cal.samples],
        "strength_samples": [{"file": s.path, "peak_force_n": s.peak_force,
                              f"strength_{su}": None if s.strength is None else s.strength / sf,
                              "columns": s.columns, "flags": list(s.flags),
                              "status_columns": s.status, "excluded": s.path in cal.excluded}
                             for s in cal.strength_samples],
        f"modulus_{mu}": stats_record(cal.modulus, mf),
        "modulus_preload_sensitivity": preload_record(cal, cal.preload_change),
        f"strength_{su}": stats_record(cal.strength, sf),
        "elongation_at_break_percent": stats_record(cal.elongation, 1e-2),
        "excluded": list(cal.excluded), "skipped": list(cal.skipped),
        "window_check": cal.window_summary or None,
        "orientations": {g.label: {"files": list(g.files),
                                   f"modulus_{mu}": stats_record(g.modulus, mf),
                                   f"strength_{su}": stats_record(g.strength, sf)}
                         for g in cal.groups},
        "warnings": list(cal.warnings),
    }
    if cal.panel is not None:
        p = cal.panel
        out["panel_law"] = {"kappa_kn_per_m_per_m": [stats_record(p.kappa1, 1e3),
                                                     stats_record(p.kappa2, 1e3)],
                            "knee_strain_percent": stats_record(p.knee, 1e-2),
                            "panel_length_mm": p.panel_length * 1e3,
                            "panel_width_mm": None if p.panel_width is None
                            else p.panel_width * 1e3}
    return out
