"""One sample: curve from an export (strain, stress or force per width), then every fit on it.

Strain comes from an extensometer column when there is one, else from crosshead displacement
over the grip distance, optionally corrected for machine compliance. Cable and dog-bone
specimens give stress (Pa); net panels give force per panel width (N/m), whose slope over the
panel length is the panel stiffness kappa = (F / w) / dl (Lambert et al. 2023, reference
section 2).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from printgen.calibrate.compliance import Compliance
from printgen.calibrate.fit import (
    ISO_WINDOW,
    BilinearFit,
    LinearFit,
    bilinear_fit,
    linear_fit,
    loading_branch,
    secant_moduli,
    steepest_fit,
    zero_at_preload,
)
from printgen.calibrate.reader import TestRecord
from printgen.calibrate.specimen import Specimen, machine_modulus
from printgen.errors import CalibrationError

DEFAULT_SECANTS = (0.005, 0.01)  # strain where secant moduli are reported (0.5 %, 1 %)


@dataclass(frozen=True)
class FitOptions:
    """window: strain (lo, hi) or None for the automatic (steepest) window; preload in N."""

    window: tuple[float, float] | None = ISO_WINDOW
    auto_span: float = 0.15
    preload: float | None = None
    secant_strains: tuple[float, ...] = DEFAULT_SECANTS
    strain_source: str = "auto"  # auto, extensometer, crosshead
    compliance: Compliance | None = None
    bilinear: bool = True


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
    """Every fit of one export (raises CalibrationError when it cannot give a modulus)."""
    x, y, source = _curve(rec, spec, opt)
    p = loading_branch(y)
    preload = opt.preload
    if preload is not None and not rec.has("force"):
        raise CalibrationError(f"{rec.path}: --preload is a force but the file has no force "
                               "column")
    force = rec.channels["force"][: p + 1] if preload is not None else None
    try:
        x_branch, y_branch = zero_at_preload(x[: p + 1], y[: p + 1], preload, force)
    except CalibrationError as exc:
        raise CalibrationError(f"{rec.path}: {exc}") from exc
    if opt.window is None:
        lin = steepest_fit(x_branch, y_branch, opt.auto_span)
    else:
        lin = linear_fit(x_branch, y_branch, *opt.window)
    bil = bilinear_fit(x_branch, y_branch) if opt.bilinear else None
    secants = secant_moduli(x_branch, y_branch, opt.secant_strains, x0=0.0, y0=float(y_branch[0]))
    peak, strength = peak_and_strength(rec, spec)
    return SampleFit(rec.path, spec, source, lin, bil, secants, peak, strength,
                     machine_modulus(rec.metadata), x_branch, y_branch)


def _curve(rec: TestRecord, spec: Specimen, opt: FitOptions) -> tuple[np.ndarray, np.ndarray, str]:
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
