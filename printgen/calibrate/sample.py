"""One sample: curve from an export (strain, stress or force per width), then every fit on it.

Strain comes from an extensometer column when there is one, else from crosshead displacement
over the grip distance, optionally corrected for machine compliance. Cable and dog-bone
specimens give stress (Pa); net panels give force per panel width (N/m), whose slope over the
panel length is the panel stiffness kappa = (F / w) / dl (Lambert et al. 2023, reference
section 2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from printgen.calibrate.compliance import Compliance
from printgen.calibrate.fit import (
    DEFAULT_ZERO,
    ISO_WINDOW,
    BilinearFit,
    LinearFit,
    bilinear_fit,
    break_index,
    linear_fit,
    loading_branch,
    secant_moduli,
    steepest_fit,
    zero_at_preload,
)
from printgen.calibrate.plausible import check_modulus, check_stress
from printgen.calibrate.reader import TestRecord
from printgen.calibrate.specimen import WAVED, Specimen, machine_modulus
from printgen.calibrate.status import set_text
from printgen.calibrate.windows import WindowCheck, check_window
from printgen.errors import CalibrationError

DEFAULT_SECANTS = (0.005, 0.01)  # strain where secant moduli are reported (0.5 %, 1 %)
PRELOAD_STEPS = (0.9, 1.1)  # preload factors for the modulus's sensitivity (+-10 %)
MAX_STRAIN = 10.0  # 1000 %: beyond any specimen's elongation, a strain given in the wrong unit


@dataclass(frozen=True)
class FitOptions:
    """window: strain (lo, hi) or None for the automatic (steepest) window; preload in N;
    zero: preload zero convention (fit.ZERO_MODES); keep_flagged: flagged samples stay in the
    statistics."""

    window: tuple[float, float] | None = ISO_WINDOW
    auto_span: float = 0.15
    preload: float | None = None
    secant_strains: tuple[float, ...] = DEFAULT_SECANTS
    strain_source: str = "auto"  # auto, extensometer, crosshead
    compliance: Compliance | None = None
    bilinear: bool = True
    zero: str = DEFAULT_ZERO
    keep_flagged: bool = False

    def __post_init__(self) -> None:
        """Refuse what would fit silently wrong: a preload that is not a positive force, a
        secant strain that is not a positive strain (nan, -1 %, 0). (The window is checked
        where it is fitted: `fit.linear_fit`.)"""
        if self.preload is not None and not (math.isfinite(self.preload) and self.preload > 0):
            raise CalibrationError(f"--preload {self.preload:g} N must be a positive force "
                                   "(the force where strain is zeroed, e.g. 2)")
        for e in self.secant_strains:
            if not (math.isfinite(e) and 0 < e <= MAX_STRAIN):
                raise CalibrationError(f"--secant strain {e * 100:g} % must be a positive strain "
                                       f"up to {MAX_STRAIN * 100:g} % (e.g. 0.5,1)")


@dataclass(frozen=True)
class SampleFit:
    """Fits of one export. y is stress (Pa), or force per width (N/m) for panels."""

    path: str
    specimen: Specimen
    strain_source: str
    linear: LinearFit
    bilinear: BilinearFit | None
    secants: dict[float, float | None]
    peak_force: float | None  # N
    strength: float | None  # Pa (panels: N/m)
    machine_modulus: float | None  # Pa, from the export's header
    x: np.ndarray = field(repr=False)  # loading branch, zeroed at the preload
    y: np.ndarray = field(repr=False)
    elongation_at_break: float | None = None  # strain from the zero to the break; None: no break
    preload_moduli: tuple[float | None, ...] | None = None  # at PRELOAD_STEPS x the preload
    flags: tuple[str, ...] = ()  # tester flags set during the test (see flag_notes)
    columns: dict[str, str] = field(default_factory=dict)  # role -> header used
    notes: tuple[str, ...] = ()  # how columns were chosen, status conventions assumed
    status: dict[str, dict[str, object]] = field(default_factory=dict)  # column -> convention
    window_check: WindowCheck | None = None  # the modulus window against the curve

    @property
    def preload_change(self) -> tuple[float | None, ...] | None:
        """Relative modulus change at PRELOAD_STEPS x the preload (None without a preload)."""
        if self.preload_moduli is None:
            return None
        return tuple(None if m is None else m / self.modulus - 1 for m in self.preload_moduli)

    @property
    def modulus(self) -> float:
        """Pa for cables and dog-bones; for panels the slope of F/w over strain (N/m)."""
        return self.linear.slope

    @property
    def kappa(self) -> float | None:
        """Low-strain panel stiffness (N/m per m) for panels, else None."""
        if self.specimen.kind != "panel":
            return None
        return self.linear.slope / _panel_length(self.specimen, self.path)


def peak_and_strength(rec: TestRecord, spec: Specimen) -> tuple[float | None, float | None]:
    """(peak force N, strength: peak stress Pa, or peak force per width N/m for panels)."""
    if rec.has("force"):
        peak = float(rec.channels["force"].max())
        if spec.kind == "panel":
            return peak, (peak / spec.width if spec.width else None)
        area = spec.cross_section()
        return peak, (peak / area if area else None)
    return None, float(rec.channels["stress"].max())


def analyse(rec: TestRecord, spec: Specimen, opt: FitOptions) -> SampleFit:
    """Every fit of one export (raises CalibrationError when it cannot give a modulus, or
    when the force, stress or modulus is implausible)."""
    peak, strength = peak_and_strength(rec, spec)
    check_stress(rec, spec, strength)
    x, y, source = strain_and_y(rec, spec, opt)
    p = loading_branch(y)
    if opt.preload is not None and not rec.has("force"):
        raise CalibrationError(f"{rec.path}: --preload is a force but the file has no force "
                               "column")
    force = rec.channels["force"][: p + 1] if opt.preload is not None else None
    lin, x_branch, y_branch, x0 = _zeroed_fit(rec.path, x[: p + 1], y[: p + 1], force,
                                              opt.preload, opt)
    check_modulus(rec, spec, lin.slope)
    moduli = None
    if opt.preload is not None:
        moduli = tuple(_modulus_or_none(rec.path, x[: p + 1], y[: p + 1], force,
                                        opt.preload * f, opt) for f in PRELOAD_STEPS)
    bil = bilinear_fit(x_branch, y_branch) if opt.bilinear else None
    secants = secant_moduli(x_branch, y_branch, opt.secant_strains, x0=0.0, y0=float(y_branch[0]))
    k = break_index(y)
    return SampleFit(rec.path, spec, source, lin, bil, secants, peak, strength,
                     machine_modulus(rec.metadata), x_branch, y_branch,
                     None if k is None else float(x[k] - x0), moduli,
                     flag_notes(rec, x - x0), dict(rec.names), rec.notes, status_record(rec),
                     check_window(x_branch, y_branch, lin, opt.auto_span))


def status_record(rec: TestRecord) -> dict[str, dict[str, object]]:
    """Each status column's convention, who decided it, and how many rows it marks."""
    return {c.name: c.record() for c in rec.status}


def flag_notes(rec: TestRecord, strain: np.ndarray | None = None) -> tuple[str, ...]:
    """One note per tester status column set during the test: where it first is set (and
    how it reads, when not the usual 1 = set)."""
    out = []
    for col in rec.status:
        if not col.on.any():
            continue
        i = int(np.argmax(col.on))
        at = f", {strain[i] * 100:.3g} % strain" if strain is not None else ""
        out.append(f"{col.name} set at line {rec.lines[i]}{at} ({int(col.on.sum())} rows"
                   f"{set_text(col)})")
    return tuple(out)


def _zeroed_fit(path: str, x: np.ndarray, y: np.ndarray, force: np.ndarray | None,
                preload: float | None, opt: FitOptions
                ) -> tuple[LinearFit, np.ndarray, np.ndarray, float]:
    """(modulus line, zeroed branch x and y, strain x0 put to zero) for one preload."""
    try:
        xb, yb, x0 = zero_at_preload(x, y, preload, force, mode=opt.zero)
        if opt.window is None:
            lin = steepest_fit(xb, yb, opt.auto_span)
        else:
            lin = linear_fit(xb, yb, *opt.window)
    except CalibrationError as exc:
        raise CalibrationError(f"{path}: {exc}") from exc
    return lin, xb, yb, x0


def _modulus_or_none(path: str, x: np.ndarray, y: np.ndarray, force: np.ndarray | None,
                     preload: float, opt: FitOptions) -> float | None:
    try:
        return _zeroed_fit(path, x, y, force, preload, opt)[0].slope
    except CalibrationError:
        return None


def strain_and_y(rec: TestRecord, spec: Specimen, opt: FitOptions
                 ) -> tuple[np.ndarray, np.ndarray, str]:
    """(strain, y, description of the strain source)."""
    deform = [r for r in ("strain", "displacement") if rec.has(r)]
    if not deform:
        raise CalibrationError(
            f"{rec.path}: no displacement, extension or strain column (columns: "
            f"{', '.join(rec.headers) or 'unnamed'}); a modulus needs one. This file gives "
            "strength only: run with --strength-only")
    y = _y(rec, spec)
    use_ext = rec.has("strain") and opt.strain_source in ("auto", "extensometer")
    if opt.strain_source == "extensometer" and not rec.has("strain"):
        raise CalibrationError(f"{rec.path}: --strain-source extensometer but no strain column")
    if use_ext:
        if opt.compliance is not None:
            raise CalibrationError(f"{rec.path}: strain from the extensometer needs no machine "
                                   "compliance correction; drop it or use --strain-source "
                                   "crosshead")
        return rec.channels["strain"], y, f"extensometer ({rec.names['strain']})"
    if not rec.has("displacement"):
        raise CalibrationError(f"{rec.path}: --strain-source crosshead but no displacement column")
    length = spec.strain_length()
    if length is None:
        raise CalibrationError(
            f"{rec.path}: strain from crosshead displacement needs the grip distance; give "
            "--grip-distance-mm (or --gauge-length-mm) or grip_distance_mm in a sidecar TOML")
    d = rec.channels["displacement"]
    what = f"crosshead ({rec.names['displacement']}) over {length * 1e3:g} mm"
    if opt.compliance is not None:
        if not rec.has("force"):
            raise CalibrationError(f"{rec.path}: compliance correction needs a force column")
        d = d - opt.compliance.machine_displacement(rec.channels["force"])
        what += f", {opt.compliance.describe()}"
    return d / length, y, what


def _y(rec: TestRecord, spec: Specimen) -> np.ndarray:
    if spec.kind == WAVED:  # fitted as force against its prediction (`calibrate.waved`)
        if not rec.has("force"):
            raise CalibrationError(f"{rec.path}: a waved test piece needs a force column")
        return rec.channels["force"]
    if spec.kind == "panel":
        if not rec.has("force"):
            raise CalibrationError(f"{rec.path}: a net panel needs a force column")
        return rec.channels["force"] / _panel_width(spec, rec.path)
    area = spec.cross_section()
    if rec.has("force") and area is not None:
        return rec.channels["force"] / area
    if rec.has("stress"):
        return rec.channels["stress"]
    raise CalibrationError(
        f"{rec.path}: stress needs the cross-section; give width and thickness (or area) in the "
        "file's metadata, with --width-mm/--thickness-mm/--area-mm2, or in a sidecar TOML")


def _panel_width(spec: Specimen, where: str) -> float:
    if spec.width is None:
        raise CalibrationError(f"{where}: a net panel needs its width (--width-mm or width_mm "
                               "in the sidecar)")
    return spec.width


def _panel_length(spec: Specimen, where: str) -> float:
    length = spec.strain_length()
    if length is None:
        raise CalibrationError(f"{where}: a net panel needs its length in the loading direction "
                               "(--gauge-length-mm or gauge_length_mm in the sidecar)")
    return length
