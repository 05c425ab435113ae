"""Calibrate one material and specimen type from several exports: read, fit, summarise.

`calibrate` is the public entry point; it returns a `Calibration` holding every sample's fits
and the statistics the profile writer, the table and the plot use. Net panels give the
piecewise-linear (bilinear) law kappa_1, knee, kappa_2 with kappa = (F / w) / dl
(Lambert et al. 2023, doi:10.1061/JHEND8.HYENG-13070; printgen reference, sections 2 and 5).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from printgen.calibrate.aggregate import Stats, spread_only, summarise
from printgen.calibrate.fit import BREAK_DROP
from printgen.calibrate.groups import Group, by_orientation, mixed_warning, orientation
from printgen.calibrate.inputs import expand
from printgen.calibrate.plausible import check_stress
from printgen.calibrate.reader import NoTableError, read_export
from printgen.calibrate.sample import (
    PRELOAD_STEPS,
    FitOptions,
    SampleFit,
    analyse,
    flag_notes,
    peak_and_strength,
    status_record,
)
from printgen.calibrate.specimen import (
    KINDS,
    WAVED,
    Specimen,
    find_sidecar,
    from_metadata,
    read_sidecar,
    resolve,
)
from printgen.calibrate.windows import machine_warning, window_warnings
from printgen.errors import CalibrationError
from printgen.inputs.profiles import profile_name
from printgen.inputs.schema import load_toml
from printgen.outputs.display import Shown, Summary

if TYPE_CHECKING:  # pragma: no cover
    from printgen.calibrate.waved import WaveCalibration

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class StrengthSample:
    """A force-only (strength) result of one export."""

    path: str
    specimen: Specimen
    peak_force: float  # N
    strength: float | None  # Pa (panels: N/m)
    flags: tuple[str, ...] = ()
    columns: dict[str, str] = field(default_factory=dict)  # role -> header used
    notes: tuple[str, ...] = ()
    status: dict[str, dict[str, object]] = field(default_factory=dict)  # column -> convention


@dataclass(frozen=True)
class PanelLawFit:
    """Mean bilinear panel law: kappas (N/m per m), knee strain from the toe-free origin."""

    kappa1: Stats
    kappa2: Stats
    knee: Stats
    panel_length: float  # m
    panel_width: float | None  # m


@dataclass(frozen=True, repr=False)
class Calibration(Shown):
    """Everything measured for one material and specimen type (shown by its statistics)."""

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
    elongation: Stats | None = None  # strain at break (a number)
    preload_change: tuple[float | None, ...] | None = None  # mean at PRELOAD_STEPS x preload
    excluded: tuple[str, ...] = ()  # flagged files left out of the statistics
    skipped: tuple[str, ...] = ()  # directory files that hold no table
    window_summary: str = ""  # how the modulus window sits on the curves (windows.py)
    orientations: dict[str, str | None] = field(default_factory=dict)  # file -> orientation
    groups: tuple[Group, ...] = ()  # per orientation, when the files mix them

    @property
    def files(self) -> tuple[str, ...]:
        return tuple(s.path for s in (*self.samples, *self.strength_samples))

    @property
    def strain_sources(self) -> tuple[str, ...]:
        return tuple(dict.fromkeys(s.strain_source for s in self.samples))

    def summary(self) -> Summary:
        """The modulus, strength and elongation (mean, sd, n) and the warnings."""
        panel = self.kind == "panel"  # N/m per unit width, else Pa shown in MPa
        unit, f = ("N/m", 1.0) if panel else ("MPa", 1e-6)

        def stats(s: Stats | None, unit: str, f: float) -> str:
            if s is None:
                return "-"
            sd = "" if s.sd is None else f" +- {s.sd * f:.3g}"
            return f"{s.mean * f:.4g}{sd} {unit} (n = {s.n})"

        rows = [("files", f"{len(self.files)} ({len(self.excluded)} left out)"),
                ("modulus", stats(self.modulus, unit, f)),
                ("strength", stats(self.strength, unit, f)),
                ("elongation at break", stats(self.elongation, "%", 100.0))]
        rows += [("warning", w) for w in self.warnings]
        return Summary(f"Calibration: {self.material} ({self.kind})", tuple(rows))


def calibrate(paths: Sequence[str | Path], *, material: str, options: FitOptions | None = None,
              specimen: Mapping[str, Any] | None = None, specimen_file: str | Path | None = None,
              columns: Mapping[str, str] | None = None, units: Mapping[str, str] | None = None,
              delimiter: str | None = None, decimal: str | None = None,
              strength_only: bool = False, conditions: str = "",
              flags: Mapping[str, str] | None = None) -> Calibration | WaveCalibration:
    """Fit every export in `paths` (files, or directories: every export in them; one
    material, one specimen type) and summarise.

    specimen : dimension options in SI (width, thickness, area, gauge_length, grip_distance)
    and `kind`; they fill what the files' metadata lines do not give.
    flags : status column -> convention (status.CONVENTIONS); default: decided from the data.
    A `specimen_file` of kind "waved" (a waved-strand coupon's, from `printgen testpieces`)
    fits the exports against its beam model instead: a `WaveCalibration`
    (`printgen.calibrate.waved`).
    """
    if not paths:
        raise CalibrationError("no tensile-test exports given")
    material = profile_name(material, "--material")  # it names <material>.toml and .png
    opt = options or FitOptions()
    kind = (specimen or {}).get("kind")
    if kind is not None and kind not in KINDS:
        raise CalibrationError(f"specimen kind {kind!r}; expected one of {', '.join(KINDS)}")
    curve = opt.compliance.source if opt.compliance and opt.compliance.force is not None else None
    files, notes = expand(paths, exclude=[p for p in (curve, specimen_file) if p])
    if specimen_file is not None and _predicted(specimen_file):
        if strength_only or kind is not None:
            raise CalibrationError(f"{specimen_file} is a waved coupon's or a square panel's "
                                   "sidecar: it is fitted against its prediction (no --kind, "
                                   "no --strength-only)")
        from printgen.calibrate.waved import calibrate_waved

        def load(path: Path):  # the force itself, as the prediction gives it
            return _load(path, {**(specimen or {}), "kind": WAVED}, specimen_file,
                         (columns, units, flags), delimiter, decimal)

        return calibrate_waved(files, load, material=material, sidecar=Path(specimen_file),
                               options=opt, conditions=conditions)
    fits: list[SampleFit] = []
    strengths: list[StrengthSample] = []
    skipped: list[str] = []
    orient: dict[str, str | None] = {}
    for path, in_dir in files:
        try:
            rec, spec = _load(path, specimen or {}, specimen_file,
                              (columns, units, flags), delimiter, decimal)
        except NoTableError:
            if not in_dir:
                raise
            skipped.append(str(path))
            continue
        if spec.kind == WAVED:
            raise CalibrationError(f"{rec.path}: its sidecar is a waved coupon's; give it with "
                                   "--specimen (it is fitted against the beam model of its "
                                   "[wave] table)")
        orient[rec.path] = orientation(rec.path, rec.metadata)
        if strength_only:
            strengths.append(_strength_sample(rec, spec))
        else:
            fits.append(analyse(rec, spec, opt))
    kinds = {s.specimen.kind for s in (*fits, *strengths)}
    if not kinds:
        raise CalibrationError(f"no exports with a table among {', '.join(skipped)}")
    if len(kinds) > 1:
        raise CalibrationError(f"exports mix specimen kinds {sorted(kinds)}; calibrate one "
                               "specimen type at a time")
    cal = Calibration(material=material, kind=kinds.pop(), options=opt, samples=tuple(fits),
                      strength_samples=tuple(strengths), conditions=conditions,
                      warnings=tuple(notes), skipped=tuple(skipped), orientations=orient)
    return _summarise(cal)


def _predicted(path: str | Path) -> bool:
    """Whether the sidecar at `path` carries a prediction its exports are fitted against: a
    waved piece's (kind waved) or a square test panel's (kind panel with a [prediction])."""
    from printgen.calibrate.waved import predicted_panel

    return read_sidecar(Path(path)).get("kind") == WAVED or predicted_panel(
        load_toml(Path(path), "specimen sidecar"))


def _strength_sample(rec, spec) -> StrengthSample:
    peak, strength = peak_and_strength(rec, spec)
    if peak is None:
        raise CalibrationError(f"{rec.path}: --strength-only needs a force column")
    check_stress(rec, spec, strength)
    return StrengthSample(rec.path, spec, peak, strength, flag_notes(rec), dict(rec.names),
                          rec.notes, status_record(rec))


def _load(path: Path, spec_opts, specimen_file, choices, delimiter, decimal):
    """(record, specimen) of one export; `choices`: the columns, units and status conventions
    the options give (they win over the sidecar's)."""
    side_path = Path(specimen_file) if specimen_file else find_sidecar(path)
    side = read_sidecar(side_path) if side_path else {}
    cols, unit_map, flag_map = ({**side.get(k, {}), **(given or {})}
                                for k, given in zip(("columns", "units", "flags"), choices,
                                                    strict=True))
    rec = read_export(path, columns=cols, units=unit_map, delimiter=delimiter, decimal=decimal,
                      flags=flag_map)
    spec = resolve(from_metadata(rec.metadata, rec.path), dict(spec_opts), side,
                   sidecar_path=str(side_path) if side_path else None)
    return rec, spec


def _summarise(cal: Calibration) -> Calibration:
    """Statistics over the samples no tester flag excludes, and the warnings, each once."""
    keep = cal.options.keep_flagged
    fits = [s for s in cal.samples if keep or not s.flags]
    forces = [s for s in cal.strength_samples if keep or not s.flags]
    flagged = [s for s in (*cal.samples, *cal.strength_samples) if s.flags]
    if flagged and not (fits or forces):
        raise CalibrationError(
            f"all {len(flagged)} samples carry tester flags ({_flag_list(flagged)}); none left "
            "for the statistics: check the tests, or keep them with --keep-flagged")
    warns = list(cal.warnings) + _column_notes((*cal.samples, *cal.strength_samples))
    action = "kept (--keep-flagged)" if keep else "excluded from the statistics"
    warns += [f"{Path(s.path).name}: {'; '.join(s.flags)}: {action}" for s in flagged]
    warns += [f"{Path(p).name}: no table of numbers, not an export: skipped" for p in cal.skipped]
    n = len(fits) + len(forces)
    warns += [w for w in [spread_only(n)] if w]
    labels = [Path(s.path).name for s in (*fits, *forces)]
    (mu, mf), (su, sf) = _units(cal)
    mod = strength = panel = elong = change = None
    bil: dict[str, Stats] = {}
    summary = ""
    if fits:
        mod = summarise([s.modulus for s in fits], what="modulus", labels=labels, unit=(mu, mf))
        warns += mod.warnings
        window = window_text(cal.options)
        more, summary = window_warnings(fits, window, (mu, mf))
        warns += [w for w in [machine_warning(fits, window, (mu, mf))] if w] + more
        with_bil = [s for s in fits if s.bilinear is not None]
        if with_bil:
            bil = {k: summarise([getattr(s.bilinear, k) for s in with_bil], what=f"bilinear {k}")
                   for k in ("slope1", "slope2", "knee")}
        if cal.kind == "panel":
            panel = _panel_law(tuple(fits))
        elong, change, more = _elongation_and_preload(fits, labels)
        warns += more
    vals = [s.strength for s in (*fits, *forces)]
    if vals and all(v is not None for v in vals):
        strength = summarise(vals, what="strength", labels=labels, unit=(su, sf))
        warns += strength.warnings
    elif vals:
        warns.append("strength not computed: cross-section (or panel width) unknown for "
                     f"{sum(v is None for v in vals)} file(s)")
    groups = by_orientation([*fits, *forces], cal.orientations)
    warns += [w for w in [mixed_warning(groups, (mu, mf), (su, sf))] if w]
    return replace(cal, modulus=mod, strength=strength, bilinear=bil, panel=panel,
                   warnings=tuple(dict.fromkeys(warns)), elongation=elong, groups=groups,
                   preload_change=change, excluded=tuple(s.path for s in flagged if not keep),
                   window_summary=summary)


def window_text(o: FitOptions) -> str:
    """The modulus window as said in warnings: '0.05-0.25 %' or 'auto (15 % of the rise)'."""
    if o.window is None:
        return f"auto ({o.auto_span:.0%} of the rise to the peak)"
    return f"{o.window[0] * 100:g}-{o.window[1] * 100:g} %"


def _units(cal: Calibration) -> tuple[tuple[str, float], tuple[str, float]]:
    """((modulus unit, factor), (strength unit, factor)) as the table shows them."""
    if cal.kind != "panel":
        return ("GPa", 1e9), ("MPa", 1e6)
    lengths = {s.specimen.strain_length() for s in cal.samples}
    length = lengths.pop() if len(lengths) == 1 else None
    return (("kN/m/m", 1e3 * length) if length else ("kN/m", 1e3)), ("kN/m", 1e3)


def _elongation_and_preload(fits: list[SampleFit], labels: list[str]):
    """(elongation at break Stats or None, mean modulus change at PRELOAD_STEPS x preload or
    None, warnings)."""
    warns = []
    breaks = [s.elongation_at_break for s in fits if s.elongation_at_break is not None]
    if len(breaks) < len(fits):
        missing = [Path(s.path).name for s in fits if s.elongation_at_break is None]
        warns.append(f"no break found in {', '.join(missing)} (the force never fell "
                     f"{BREAK_DROP:.0%} below its peak): elongation at break left out for them")
    elong = summarise(breaks, what="elongation at break", unit=("%", 1e-2)) if breaks else None
    change = None
    if fits[0].preload_change is not None:
        change = tuple(_mean_or_none([s.preload_change[k] for s in fits if s.preload_change])
                       for k in range(len(PRELOAD_STEPS)))
    return elong, change, warns


def _mean_or_none(values: list[float | None]) -> float | None:
    v = [x for x in values if x is not None]
    return float(sum(v) / len(v)) if v else None


def _flag_list(samples) -> str:
    return "; ".join(f"{Path(s.path).name}: {', '.join(s.flags)}" for s in samples)


def _column_notes(samples) -> list[str]:
    """Each column-choice note once, with the files it applies to."""
    files: dict[str, list[str]] = {}
    for s in samples:
        for note in s.notes:
            files.setdefault(note, []).append(Path(s.path).name)
    total = len(samples)
    return [f"{note} ({_which(names, total)})" for note, names in files.items()]


def _which(names: list[str], total: int) -> str:
    """'all N files' when a note holds for every one of several files, else their names."""
    return f"all {total} files" if len(names) == total > 1 else ", ".join(names)


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
