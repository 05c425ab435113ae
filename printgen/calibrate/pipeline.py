"""Calibrate one material and specimen type from several exports: read, fit, summarise.

`calibrate` is the public entry point; it returns a `Calibration` holding every sample's fits
and the statistics the profile writer, the table and the plot use. Net panels give the
piecewise-linear (bilinear) law kappa_1, knee, kappa_2 with kappa = (F / w) / dl
(Lambert et al. 2023, doi:10.1061/JHEND8.HYENG-13070; printgen reference, sections 2 and 5).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from printgen.calibrate.aggregate import Stats, summarise
from printgen.calibrate.reader import read_export
from printgen.calibrate.sample import FitOptions, SampleFit, analyse, peak_and_strength
from printgen.calibrate.specimen import (
    KINDS,
    Specimen,
    find_sidecar,
    from_metadata,
    read_sidecar,
    resolve,
)
from printgen.errors import CalibrationError

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class StrengthSample:
    """A force-only (strength) result of one export."""

    path: str
    specimen: Specimen
    peak_force: float  # N
    strength: float | None  # Pa (panels: N/m)


@dataclass(frozen=True)
class PanelLawFit:
    """Mean bilinear panel law: kappas (N/m per m), knee strain from the toe-free origin."""

    kappa1: Stats
    kappa2: Stats
    knee: Stats
    panel_length: float  # m
    panel_width: float | None  # m


@dataclass(frozen=True)
class Calibration:
    """Everything measured for one material and specimen type."""

    material: str
    kind: str
    options: FitOptions
    samples: tuple[SampleFit, ...] = ()
    strength_samples: tuple[StrengthSample, ...] = ()
    modulus: Stats | None = None  # Pa (panels: slope of F/w over strain, N/m)
    strength: Stats | None = None  # Pa (panels: N/m)
    bilinear: dict[str, Stats] = field(default_factory=dict)
    panel: PanelLawFit | None = None
    conditions: str = ""
    warnings: tuple[str, ...] = ()

    @property
    def files(self) -> tuple[str, ...]:
        return tuple(s.path for s in (*self.samples, *self.strength_samples))

    @property
    def strain_sources(self) -> tuple[str, ...]:
        return tuple(dict.fromkeys(s.strain_source for s in self.samples))


def calibrate(paths: Sequence[str | Path], *, material: str, options: FitOptions | None = None,
              specimen: Mapping[str, Any] | None = None, specimen_file: str | Path | None = None,
              columns: Mapping[str, str] | None = None, units: Mapping[str, str] | None = None,
              delimiter: str | None = None, decimal: str | None = None,
              strength_only: bool = False, conditions: str = "") -> Calibration:
    """Fit every export in `paths` (one material, one specimen type) and summarise.

    specimen : dimension options in SI (width, thickness, area, gauge_length, grip_distance)
    and `kind`; they fill what the files' metadata lines do not give.
    """
    if not paths:
        raise CalibrationError("no tensile-test exports given")
    opt = options or FitOptions()
    kind = (specimen or {}).get("kind")
    if kind is not None and kind not in KINDS:
        raise CalibrationError(f"specimen kind {kind!r}; expected one of {', '.join(KINDS)}")
    fits: list[SampleFit] = []
    strengths: list[StrengthSample] = []
    for p in paths:
        rec, spec = _load(Path(p), specimen or {}, specimen_file, columns, units, delimiter,
                          decimal)
        if strength_only:
            peak, strength = peak_and_strength(rec, spec)
            if peak is None:
                raise CalibrationError(f"{rec.path}: --strength-only needs a force column")
            strengths.append(StrengthSample(rec.path, spec, peak, strength))
        else:
            fits.append(analyse(rec, spec, opt))
    kinds = {s.specimen.kind for s in (*fits, *strengths)}
    if len(kinds) > 1:
        raise CalibrationError(f"exports mix specimen kinds {sorted(kinds)}; calibrate one "
                               "specimen type at a time")
    cal = Calibration(material=material, kind=kinds.pop(), options=opt, samples=tuple(fits),
                      strength_samples=tuple(strengths), conditions=conditions)
    return _summarise(cal)


def _load(path: Path, spec_opts, specimen_file, columns, units, delimiter, decimal):
    side_path = Path(specimen_file) if specimen_file else find_sidecar(path)
    side = read_sidecar(side_path) if side_path else {}
    cols = {**side.get("columns", {}), **(columns or {})}
    unit_map = {**side.get("units", {}), **(units or {})}
    rec = read_export(path, columns=cols, units=unit_map, delimiter=delimiter, decimal=decimal)
    spec = resolve(from_metadata(rec.metadata, rec.path), dict(spec_opts), side,
                   sidecar_path=str(side_path) if side_path else None)
    return rec, spec


def _summarise(cal: Calibration) -> Calibration:
    labels = [Path(f).name for f in cal.files]
    warns: list[str] = []
    mod = strength = panel = None
    bil: dict[str, Stats] = {}
    if cal.samples:
        mod = summarise([s.modulus for s in cal.samples], what="modulus", labels=labels)
        warns += mod.warnings
        with_bil = [s for s in cal.samples if s.bilinear is not None]
        if with_bil:
            bil = {k: summarise([getattr(s.bilinear, k) for s in with_bil], what=f"bilinear {k}",
                                 quiet=True)
                   for k in ("slope1", "slope2", "knee")}
        if cal.kind == "panel":
            panel = _panel_law(cal.samples)
    vals = [s.strength for s in (*cal.samples, *cal.strength_samples)]
    if vals and all(v is not None for v in vals):
        strength = summarise(vals, what="strength", labels=labels)
        warns += [w for w in strength.warnings if mod is None or "only" not in w]
    elif vals:
        warns.append("strength not computed: cross-section (or panel width) unknown for "
                     f"{sum(v is None for v in vals)} file(s)")
    return Calibration(cal.material, cal.kind, cal.options, cal.samples, cal.strength_samples,
                       mod, strength, bil, panel, cal.conditions, tuple(warns))


def _panel_law(samples: tuple[SampleFit, ...]) -> PanelLawFit:
    k1, k2, knee = [], [], []
    lengths = {s.specimen.strain_length() for s in samples}
    widths = {s.specimen.width for s in samples}
    for s in samples:
        b, length = s.bilinear, s.specimen.strain_length()
        if b is None or length is None:
            raise CalibrationError(f"{s.path}: a panel law needs the bilinear fit and the panel "
                                   "length")
        if not (b.slope1 > 0 and b.slope2 > 0):
            raise CalibrationError(f"{s.path}: bilinear slopes {b.slope1 / length:.4g} and "
                                   f"{b.slope2 / length:.4g} N/m/m; a panel law needs both > 0")
        k1.append(b.slope1 / length)
        k2.append(b.slope2 / length)
        knee.append(b.knee + b.intercept / b.slope1)  # from the toe-compensated origin
    if len(lengths) > 1:
        raise CalibrationError(f"panels of different lengths {sorted(lengths)} m: kappa depends "
                               "on the panel length; calibrate each length separately")
    return PanelLawFit(summarise(k1, what="kappa1"), summarise(k2, what="kappa2"),
                       summarise(knee, what="knee strain"), lengths.pop(),  # type: ignore[arg-type]
                       widths.pop() if len(widths) == 1 else None)
