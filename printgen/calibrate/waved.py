"""Calibrate waved-strand test pieces (`printgen testpieces` of a waved design, sidecar kind
"waved"): their exports against the beam model of their strands (`printgen.solver.strand_curve`).

The sidecar's `[wave]` table gives the model's inputs: the chord, the wave, the strands side by
side, their section, and the material law the prediction assumed (stress knees and slopes); a
waved test panel's (`test = "panel"`) adds its simulated free test (strains and force per
clamp width). Held as designed (assumed, not measured): the wave's geometry, the section, the
ends clamped by the gripped tabs (the panel: its pin-jointed net between the clamps), the
shape of the material law. Measured: the one parameter the beam model leaves to the material,
the scale of its law. The strand's chord force is linear in a scale of the material's stress
law at every strain (every fibre's stress scales with it, the geometry does not), and so is
a displacement-controlled panel's (every strand's law scales, the equilibrium positions do
not move), so the measured force is s x the prediction, and s is a linear least-squares fit
over the loading branch: s = sum(F p) / sum(p^2). The measured law is s x the assumed one (its
modulus s x the assumed modulus). A free panel the solver finds a mechanism has no prediction
to fit (refused, with the fix).

The shape is the model's check: a continuous bilinear fit (`fit.bilinear_fit`) of the measured
curve and of the fitted prediction at the same strains gives the knee strain and the two
slopes of each; their knees and the ratio of their slopes do not depend on s (the wave's
geometry sets them). The fit reaches the largest strain predicted (the coupon: the strain the
design's strand law is solved to, `curved.curve_strains`, the range the net solver uses the
curve over); the data beyond it are left out (said in the warnings).

A square net's straight test panel (sidecar kind "panel" with a `[prediction]` table, from
`printgen testpieces` of a straight square design) is fitted the same way: its strands along
the load lie along it from the start, so its simulated free test is linear in the law's scale
too (no wave: the prediction is the straight strands' law through the panel test).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from printgen.barrier.patterns.curved import curve_strains
from printgen.calibrate.aggregate import Stats, summarise
from printgen.calibrate.fit import BilinearFit, bilinear_fit, loading_branch, zero_at_preload
from printgen.calibrate.sample import FitOptions, flag_notes, strain_and_y
from printgen.errors import CalibrationError
from printgen.inputs.schema import Field, load_toml, positive, read_table
from printgen.outputs.display import Shown, Summary
from printgen.solver import Law
from printgen.solver.strand_curve import Strand, StrandCurve, strand_curve

KIND = "waved"
WAVE = [
    positive("chord_mm", 1e4, si=False), positive("amplitude_mm", 1e3, si=False),
    Field("half_waves", int, lo=1), Field("strands", int, lo=1, required=False, default=1),
    positive("strand_width_mm", 1e3, si=False), positive("thickness_mm", 1e3, si=False),
    Field("material", str), Field("law_source", str, required=False, default=""),
    Field("stress_knees", list, items=float), Field("stress_slopes_mpa", list, items=float),
    Field("test", str, choices=("coupon", "panel"), required=False, default="coupon"),
    Field("panel_strains", list, items=float, required=False, default=[]),
    Field("panel_n_per_m", list, items=float, required=False, default=[]),
    Field("panel_hold_share", float, lo=0.0, required=False, default=0.0),
]
PREDICTION = "prediction"  # a straight square panel's table: its simulated free test
PANEL_PREDICTION = [
    Field("material", str), Field("law_source", str, required=False, default=""),
    Field("stress_knees", list, items=float), Field("stress_slopes_mpa", list, items=float),
    Field("strands", int, lo=1), positive("strand_width_mm", 1e3, si=False),
    positive("thickness_mm", 1e3, si=False), positive("mesh_mm", 1e4, si=False),
    Field("panel_strains", list, items=float), Field("panel_n_per_m", list, items=float),
    Field("panel_hold_share", float, lo=0.0, required=False, default=0.0),
]
MECHANISM = 0.5  # a free panel whose simulated clamp force the solver's hold carries more
# than half of is a mechanism (printgen panel's measure): its curve is no prediction
# A bilinear fit needs a knee with points on both sides; fewer than this many loading points
# (or a curve that never rises) leaves nothing to fit.
MIN_POINTS = 20
KNEE_TOL = 0.25  # |measured / predicted knee - 1| above this: the model's knee is off. The
# knee strain is about the excess length, ~ a^2: a knee 25 % off is an amplitude about 12 %
# off, 0.12 mm or more on the 1-1.5 mm waves of a 1:40 net, beyond the 0.1 mm a printer
# places a bead to (`parts.geometry.wave`)


@dataclass(frozen=True)
class WaveModel:
    """The beam model of the coupon's strands (SI): chord (m), wave amplitude (m) and
    half-waves, strands side by side, in-plane width and thickness (m), the material's stress
    law (Pa per unit strain) the prediction assumed, its material and source."""

    chord: float
    amplitude: float
    half_waves: int
    strands: int
    width: float
    thickness: float
    stress: Law
    material: str
    law_source: str
    panel_strains: tuple[float, ...] = ()  # a waved test panel's: its simulated free test
    panel_n_per_m: tuple[float, ...] = ()
    panel_width: float = 0.0  # m, the panel's clamp width (its force per width is fitted)

    @property
    def panel(self) -> bool:
        return bool(self.panel_strains)

    @property
    def straight(self) -> bool:
        """A straight square panel's model (no wave: `_straight_panel`)."""
        return self.amplitude == 0

    @property
    def unit(self) -> str:
        return "N/m" if self.panel else "N"

    def predict(self, strain: np.ndarray) -> np.ndarray:
        """The predicted coupon force (N, all strands) or panel force per width (N/m)."""
        if self.panel:
            return np.interp(strain, (0.0, *self.panel_strains), (0.0, *self.panel_n_per_m))
        return self.strands * self.curve().law().force_and_tangent(strain)[0]

    def measured(self, force: np.ndarray) -> np.ndarray:
        """The export's force as the prediction reads it (per clamp width for a panel)."""
        return force / self.panel_width if self.panel else force

    def strand(self) -> Strand:
        return Strand(self.chord, self.amplitude, self.half_waves, self.width, self.thickness,
                      self.stress)

    def top(self) -> float:
        """The largest strain predicted: the chord strain the design's strand law is solved to
        (`curve_strains`), or the panel's simulated test's last strain."""
        if self.panel:
            return self.panel_strains[-1]
        return float(curve_strains(self.strand().excess())[-1])

    def curve(self) -> StrandCurve:
        return _solved(self)


@lru_cache(maxsize=8)
def _solved(m: WaveModel) -> StrandCurve:
    s = m.strand()
    strains = curve_strains(s.excess())  # the design's strand law's points (`scene.waved`)
    return strand_curve(s, np.union1d(strains, [k for k in s.stress.knees if k < strains[-1]]))


def read_wave(path: str | Path) -> WaveModel:
    """The `[wave]` table of the sidecar at `path` as a WaveModel; CalibrationError naming
    what is missing or wrong."""
    data = load_toml(path, "specimen sidecar")
    if predicted_panel(data):
        return _straight_panel(data, path)
    if data.get("kind") != KIND:
        raise CalibrationError(f"{path}: kind {data.get('kind')!r}; a waved coupon's sidecar "
                               f"has kind = \"{KIND}\" (printgen testpieces writes it)")
    if "wave" not in data:
        raise CalibrationError(f"{path}: no [wave] table; a waved coupon is calibrated against "
                               "the beam model of its strands, whose inputs the [wave] table "
                               "gives: use the sidecar printgen testpieces wrote")
    t = read_table(data["wave"], WAVE, where=f"{path} [wave]")
    model = WaveModel(t["chord_mm"] * 1e-3, t["amplitude_mm"] * 1e-3, t["half_waves"],
                      t["strands"], t["strand_width_mm"] * 1e-3, t["thickness_mm"] * 1e-3,
                      _stress_law(t, f"{path} [wave]"), t["material"], t["law_source"])
    return model if t["test"] == "coupon" else _panel(model, t, data, path)


def predicted_panel(data: dict[str, Any]) -> bool:
    """Whether sidecar `data` is a straight square panel's (kind "panel" with a
    `[prediction]` table), fitted as the waved pieces are."""
    return data.get("kind") == "panel" and PREDICTION in data


def _straight_panel(data: dict[str, Any], path: str | Path) -> WaveModel:
    """The straight square panel of sidecar `data`'s `[prediction]` table as a WaveModel
    without a wave (amplitude 0: its chord is the mesh side)."""
    where = f"{path} [{PREDICTION}]"
    t = read_table(data[PREDICTION], PANEL_PREDICTION, where=where)
    model = WaveModel(t["mesh_mm"] * 1e-3, 0.0, 0, t["strands"], t["strand_width_mm"] * 1e-3,
                      t["thickness_mm"] * 1e-3, _stress_law(t, where), t["material"],
                      t["law_source"])
    return _panel(model, t, data, path)


def _stress_law(t: dict[str, Any], where: str) -> Law:
    """The stress law (Pa per unit strain) of a read table's stress_knees and
    stress_slopes_mpa; CalibrationError naming `where` unless it is a law."""
    knees, slopes = tuple(t["stress_knees"]), tuple(v * 1e6 for v in t["stress_slopes_mpa"])
    if len(slopes) != len(knees) + 1 or not all(v > 0 for v in slopes) \
            or any(b <= a for a, b in zip((0.0, *knees), knees, strict=False)):
        raise CalibrationError(
            f"{where}: stress law knees {list(knees)} and slopes "
            f"{list(t['stress_slopes_mpa'])} MPa: need increasing knees above 0 and one more "
            "slope than knees, every slope > 0")
    return Law(knees, slopes)


def _panel(model: WaveModel, t: dict[str, Any], data: dict[str, Any],
           path: str | Path) -> WaveModel:
    """`model` with the waved test panel's simulated free test (its [wave] table's panel_*
    keys, its clamp width the sidecar's width_mm)."""
    e, n = tuple(t["panel_strains"]), tuple(t["panel_n_per_m"])
    if len(e) < 2 or len(e) != len(n) or any(b <= a for a, b in zip((0.0, *e), e,
                                                                      strict=False)):
        raise CalibrationError(f"{path} [wave]: a panel's panel_strains ({len(e)}) and "
                               f"panel_n_per_m ({len(n)}) must be as many, at least 2, the "
                               "strains increasing from above 0: use the sidecar printgen "
                               "testpieces wrote")
    if t["panel_hold_share"] > MECHANISM:
        raise CalibrationError(
            f"{path}: the simulated free panel is a mechanism (the solver's hold carries "
            f"{t['panel_hold_share']:.2g} of its clamp force, over {MECHANISM:g}): its pin-"
            "jointed free net has no stiffness of its own until it locks, so its curve "
            "predicts nothing a material law could be fitted to (the printed panel's low-strain "
            "force comes from its rigid junctions). Calibrate the material with the waved "
            "coupons (wave-coupon.specimen.toml) and compare this panel's curve with "
            "panel-expected.csv (between its free and blocked columns)")
    width = data.get("width_mm")
    if not isinstance(width, (int, float)) or not width > 0:
        raise CalibrationError(f"{path}: a waved panel's sidecar needs width_mm (its clamp "
                               f"width, > 0), got {width!r}")
    return replace(model, panel_strains=e, panel_n_per_m=n, panel_width=width * 1e-3)


@dataclass(frozen=True)
class WaveSample:
    """One export against the model: strain source, the fitted scale s of the material law,
    the RMS of the measured force about s x the prediction over its largest force, the
    bilinear fits of the measured and of the fitted predicted curve at the same strains, the
    strain range fitted (the top: the model's) and the points beyond it left out."""

    path: str
    strain_source: str
    scale: float
    rms: float
    measured: BilinearFit
    predicted: BilinearFit
    strain_max: float
    left_out: int
    flags: tuple[str, ...] = ()
    x: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False)
    force: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False)


def fit_sample(path: str, x: np.ndarray, force: np.ndarray, model: WaveModel,
               strain_source: str = "", flags: tuple[str, ...] = ()) -> WaveSample:
    """Fit one loading branch (strain from zero, force N) against `model` (module docstring)."""
    top = model.top()
    keep = x <= top
    xs, fs = x[keep], force[keep]
    if xs.size < MIN_POINTS or not np.any(fs > 0):
        raise CalibrationError(f"{path}: {xs.size} loading points up to {top:.1%} chord strain "
                               f"(the model's range), need {MIN_POINTS} with a rising force: "
                               "check the strain column and the gauge (the chord) in the "
                               "sidecar")
    pred = model.predict(xs)
    scale = float(fs @ pred / (pred @ pred))
    if not (math.isfinite(scale) and scale > 0):
        raise CalibrationError(f"{path}: the measured force does not follow the prediction "
                               f"(fitted scale {scale:g}); check the force column's unit and "
                               "sign")
    fitted = scale * pred
    rms = float(np.sqrt(np.mean((fs - fitted) ** 2)) / np.max(fitted))
    try:
        meas, model_fit = bilinear_fit(xs, fs), bilinear_fit(xs, fitted)
    except CalibrationError as exc:
        raise CalibrationError(f"{path}: {exc}") from exc
    return WaveSample(path, strain_source, scale, rms, meas, model_fit, float(xs[-1]),
                      int(np.sum(~keep)), flags, xs, fs)


@dataclass(frozen=True, repr=False)
class WaveCalibration(Shown):
    """Waved coupons of one material against the beam model: per sample fits, the scale s
    of the material law over them, the modulus it gives (s x the assumed initial modulus),
    and the measured and predicted knees and slope ratios."""

    material: str
    model: WaveModel
    samples: tuple[WaveSample, ...]
    scale: Stats
    conditions: str = ""
    warnings: tuple[str, ...] = ()
    kind: str = KIND
    strength_samples: tuple = ()  # a waved coupon gives no strength: its break is the wave's
    groups: tuple = ()

    @property
    def files(self) -> tuple[str, ...]:
        return tuple(s.path for s in self.samples)

    @property
    def modulus(self) -> float:
        """Measured initial modulus (Pa): s x the assumed law's."""
        return self.scale.mean * float(self.model.stress.slopes[0])

    def knees(self) -> tuple[Stats, Stats]:
        """(measured, predicted) bilinear knee strains."""
        return (summarise([s.measured.knee for s in self.samples], what="measured knee"),
                summarise([s.predicted.knee for s in self.samples], what="predicted knee"))

    def ratios(self) -> tuple[Stats, Stats]:
        """(measured, predicted) ratio of the bilinear fits' second slope to their first."""
        return (summarise([s.measured.slope2 / s.measured.slope1 for s in self.samples],
                          what="measured slope ratio"),
                summarise([s.predicted.slope2 / s.predicted.slope1 for s in self.samples],
                          what="predicted slope ratio"))

    def assumptions(self) -> tuple[str, str]:
        """(what was measured, what was assumed)."""
        m = self.model
        if m.straight:
            return ((f"the scale of {m.material}'s stress law through the square panel's "
                     f"simulated free test (x {self.scale.mean:.4g}: initial modulus "
                     f"{self.modulus / 1e6:.4g} MPa)"),
                    (f"{m.strands} straight strands along the load between the clamps (mesh "
                     f"side {m.chord * 1e3:g} mm, clamps {m.panel_width * 1e3:.4g} mm wide), "
                     "each strained as the panel, the strands across carrying nothing; the "
                     f"section {m.width * 1e3:g} x {m.thickness * 1e3:.4g} mm, the junctions "
                     f"taken as strand, the shape of the material law "
                     f"({m.law_source or m.material})"))
        piece = (f"the panel's simulated free test (the net's strands pulling with the beam "
                 f"model's curve, pin-jointed, clamps {m.panel_width * 1e3:.4g} mm wide)"
                 if m.panel else f"{m.strands} strands, ends clamped by the gripped tabs")
        return ((f"the scale of {m.material}'s stress law through the beam model "
                 f"(x {self.scale.mean:.4g}: initial modulus {self.modulus / 1e6:.4g} MPa)"),
                (f"the wave as designed ({m.amplitude * 1e3:g} mm amplitude, {m.half_waves} "
                 f"half-wave(s) over a {m.chord * 1e3:.4g} mm chord), the section "
                 f"{m.width * 1e3:g} x {m.thickness * 1e3:.4g} mm, {piece}, the shape of the "
                 f"material law ({m.law_source or m.material}), compression as tension"))

    def summary(self) -> Summary:
        (km, kp), (rm, rp) = self.knees(), self.ratios()
        measured, assumed = self.assumptions()
        sd = "" if self.scale.sd is None else f" +- {self.scale.sd:.3g}"
        rows = [("files", str(len(self.samples))),
                ("law scale s", f"{self.scale.mean:.4g}{sd} (n = {self.scale.n})"),
                ("modulus", f"{self.modulus / 1e6:.4g} MPa (assumed "
                            f"{float(self.model.stress.slopes[0]) / 1e6:.4g} MPa)"),
                ("knee strain", f"measured {km.mean:.2%}, predicted {kp.mean:.2%} "
                                f"({km.mean / kp.mean - 1:+.0%})"),
                ("slope ratio", f"measured {rm.mean:.3g}, predicted {rp.mean:.3g}"),
                ("RMS about s x prediction", f"{max(s.rms for s in self.samples):.1%} of "
                                             "the largest force (worst file)"),
                ("measured", measured), ("assumed", assumed)]
        rows += [("warning", w) for w in self.warnings]
        piece = ("Square-panel" if self.model.straight else
                 "Waved-panel" if self.model.panel else "Waved-coupon")
        return Summary(f"{piece} calibration: {self.material}", tuple(rows))

    def to_record(self) -> dict[str, Any]:
        (km, kp), (rm, rp) = self.knees(), self.ratios()
        measured, assumed = self.assumptions()
        return {"material": self.material, "kind": "panel" if self.model.straight else KIND,
                "files": list(self.files),
                "piece": "panel" if self.model.panel else "coupon", "unit": self.model.unit,
                "law_scale": {"mean": self.scale.mean, "sd": self.scale.sd, "n": self.scale.n},
                "modulus_mpa": self.modulus / 1e6,
                "assumed_modulus_mpa": float(self.model.stress.slopes[0]) / 1e6,
                "knee_strain": {"measured": km.mean, "predicted": kp.mean},
                "slope_ratio": {"measured": rm.mean, "predicted": rp.mean},
                "measured": measured, "assumed": assumed, "warnings": list(self.warnings),
                "samples": [{"file": Path(s.path).name, "strain_source": s.strain_source,
                             "law_scale": s.scale, "rms_of_max": s.rms,
                             "knee_measured": s.measured.knee,
                             "knee_predicted": s.predicted.knee,
                             "slopes_measured_n": [s.measured.slope1, s.measured.slope2],
                             "slopes_predicted_n": [s.predicted.slope1, s.predicted.slope2],
                             "strain_max": s.strain_max, "points_beyond_model": s.left_out,
                             "flags": list(s.flags)} for s in self.samples]}


def calibrate_waved(files: list[tuple[Path, Any]], load, *, material: str, sidecar: Path,
                    options: FitOptions, conditions: str = "") -> WaveCalibration:
    """Fit every export of `files` ((path, in a directory) pairs; `load(path)` gives its
    record and specimen) against the model of `sidecar`'s `[wave]` table."""
    model = read_wave(sidecar)
    samples = []
    for path, _ in files:
        rec, spec = load(path)
        x, force, source = strain_and_y(rec, spec, options)
        p = loading_branch(force)
        xb, fb, _ = zero_at_preload(x[: p + 1], model.measured(force[: p + 1]),
                                    options.preload, force[: p + 1], mode=options.zero)
        samples.append(fit_sample(rec.path, xb, fb, model, source, flag_notes(rec)))
    scale = summarise([s.scale for s in samples], what="law scale",
                      labels=[Path(s.path).name for s in samples])
    cal = WaveCalibration(material, model, tuple(samples), scale, conditions)
    return _with_warnings(cal)


def _with_warnings(cal: WaveCalibration) -> WaveCalibration:
    warns = list(cal.scale.warnings)
    km, kp = cal.knees()
    if _has_knee(cal.model) and abs(km.mean / kp.mean - 1) > KNEE_TOL:
        warns.append(f"the measured knee ({km.mean:.2%} chord strain) is "
                     f"{km.mean / kp.mean - 1:+.0%} off the beam model's ({kp.mean:.2%}), beyond "
                     f"{KNEE_TOL:.0%}: the printed wave is not the designed one (measure its "
                     "amplitude) or the tabs turned in the grips; the fitted scale then mixes "
                     "geometry into the material")
    left = [s for s in cal.samples if s.left_out]
    if left:
        warns.append(f"points beyond {cal.model.top():.1%} chord strain (the range the design's "
                     f"strand law is solved over) left out of the fit in {len(left)} file(s)")
    ext = [Path(s.path).name for s in cal.samples if s.strain_source.startswith("extensometer")]
    if ext:
        warns.append(f"strain from an extensometer in {', '.join(ext)}: the prediction is over "
                     f"the chord ({cal.model.chord * 1e3:.4g} mm, tab edge to tab edge); if the "
                     "extensometer spans less, rerun with --strain-source crosshead")
    flagged = [s for s in cal.samples if s.flags]
    warns += [f"{Path(s.path).name}: {'; '.join(s.flags)}" for s in flagged]
    return WaveCalibration(cal.material, cal.model, cal.samples, cal.scale, cal.conditions,
                           tuple(dict.fromkeys(warns)))


def _has_knee(m: WaveModel) -> bool:
    """Whether the model's curve has a knee to check: a wave's, or a straight panel's law's
    within the strains it predicts (a straight line's bilinear knee is noise)."""
    return not m.straight or any(k < m.top() for k in m.stress.knees)


def measured_wave_tables(cal: WaveCalibration, prov: dict[str, Any]) -> dict[str, dict]:
    """The `[measured.*]` tables (file units) the fit gives: the assumed material's law scaled
    by s, as the law the verification reads. A material with a measured panel law: that law
    with its kappas times s (its knees, the tested panel and net kept: the stress law the
    design's strands take from it scales with its kappas); else its modulus times s."""
    from printgen.calibrate.profile_writer import _r
    from printgen.inputs.materials import load_material

    s, mat = cal.scale, load_material(cal.model.material)
    measured, assumed = cal.assumptions()
    piece = ("a square net's test panel through its simulated test" if cal.model.straight
             else "waved-strand coupons through the printgen beam model")
    how = f"{piece}: measured {measured}; assumed {assumed}"
    prov = {**prov, "conditions": f"{prov.get('conditions', '')}; {how}".lstrip("; ")}
    pl = mat.panel_law
    if pl is None:
        table: dict[str, Any] = {"value_gpa": _r(cal.modulus / 1e9), "n_samples": s.n}
        if s.sd is not None and s.sd > 0:
            table["sd_gpa"] = _r(s.sd * float(cal.model.stress.slopes[0]) / 1e9)
        return {"tensile_modulus": table | prov}
    law: dict[str, Any] = {"knee_strain_percent": [_r(k * 100) for k in pl.knee_strains],
                           "kappa_kn_per_m_per_m": [_r(k * s.mean / 1e3) for k in pl.kappas],
                           "panel_length_mm": _r(pl.panel_length * 1e3),
                           "test_mode": pl.test_mode, "n_samples": s.n}
    for key, v in (("panel_width_mm", pl.panel_width), ("strand_width_mm", pl.strand_width),
                   ("strand_thickness_mm", pl.strand_thickness),
                   ("mesh_along_load_mm", pl.mesh_along_load),
                   ("mesh_across_load_mm", pl.mesh_across_load)):
        if v is not None:
            law[key] = _r(v * 1e3)
    return {"panel_law": law | prov}

