"""Uncertainty bands of the pre-print check: the printed model swept for its nominal design
and for each uncertain input it depends on, one at a time, and the min/max envelope of the
normalised deformations at every relative loading.

Variants of the printed model (`model_variants`):
- measured modulus +- SD of each material whose profile records an SD (`sd_gpa`); the net's
  strands follow it only when their law comes from the modulus (a panel law has no SD), the
  printed border frame always does; the cables follow their material's SD;
- the panel law's geometry assumption: the law's tested net (strand and mesh recorded in the
  profile, an assumption when the source does not give it) against the alternative that the
  tested panel had the design's own strands and mesh (the law used without rescaling);
- the mounting in the flume, when the scene offers more than one (`mounting_options`);
- initial slack of the printed net, 0 to `SLACK_MAX` (0 is the nominal).

Cheap sweeps: the variants run on the coarsest solver net (the design's mesh times k, k in
`COARSENINGS`, strands k times stiffer: the same membrane stiffness per unit width) whose
nominal curves stay within `REFINE_TOL` of the design's own net (the refinement test, run
with the nominal); a variant's curve is then the nominal curve plus the variant's change on
the coarse net. Every sweep warm-starts each level from the previous one (solver.solve_path)
and the runs go to worker processes in parallel.
"""

from __future__ import annotations

import dataclasses
import inspect
import time
from collections.abc import Callable
from concurrent.futures import Future
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from printgen.barrier.loads import LoadCase
from printgen.barrier.patterns import get_pattern
from printgen.barrier.patterns.diamond import diamond_factor
from printgen.design.record import Design
from printgen.design.section import area_m2
from printgen.errors import GeometryError
from printgen.inputs.materials import load_material
from printgen.inputs.prototype import Prototype
from printgen.trace import span
from printgen.units import MM
from printgen.verification.compare import METRICS
from printgen.verification.scenes import BarrierScene, model_scene
from printgen.verification.verify import Run, load_keywords, sweep
from printgen.workers import collect, submit_jobs

SLACK_MAX = 0.01  # initial slack of the printed net, upper end of the range (0-1 %)
COARSENINGS = (2, 3)  # mesh multipliers tried in turn for the variant sweeps
REFINE_TOL = 0.01  # a coarser net is used when no nominal curve moves by more than 1 % of its peak
SAME = 1e-9  # relative change below which an alternative equals the nominal (not run)


@dataclass(frozen=True)
class Variant:
    """One uncertain input of the printed model moved from its nominal value.

    net_factor, frame_factor, cable_factor : multipliers on the force laws of the net's
    strands, the printed border frame and the border cables; slack : relative initial slack
    of every strand and cable; mounting : the scene's mounting option (None: the default).
    """

    label: str = "nominal"
    net_factor: float = 1.0
    frame_factor: float = 1.0
    cable_factor: float = 1.0
    slack: float = 0.0
    mounting: str | None = None
    source: str = ""
    orientation: str | None = None  # panel-test orientation of the net's law (None: profile's)
    pressure: str = "flow"  # the water's force along the flow or normal to the net (scenes)
    span: float | None = None  # lateral supports this far apart (m; None: the printed width)
    net_law: str = "formula"  # strand law: diamond formula or the virtual panel test's (forms)
    bed: str = "free"  # the net's bottom row free or held on the flume bed (forms)
    routing: str = "in-line"  # the sensor wires beyond the right edge (forms.ROUTINGS)


def mounting_options() -> tuple[str, ...]:
    """Mounting variants the model scene offers (its `mounting` keyword), default first;
    empty when the scene has a single mounting."""
    param = inspect.signature(model_scene).parameters.get("mounting")
    if param is None:
        return ()
    from printgen.verification import scenes

    return tuple(getattr(scenes, "MOUNTINGS", ()))


def model_variants(d: Design, mounting: str | None = None, free_section: float | None = None
                   ) -> tuple[list[Variant], list[str]]:
    """The variants of design `d` to sweep, and one note per uncertainty left out and why;
    `mounting` is the nominal run's (the other mountings become variants); `free_section` m:
    the flume's free section, when narrower than the net (a mounting-span variant)."""
    out, notes = [], []
    net = load_material(d.net.material)
    panel = net.panel_law
    law_from_modulus = panel is None or not panel.has_geometry
    e, source = net.modulus()
    sd = net.measured_modulus.sd if source == "measured" and net.measured_modulus else None
    if sd:
        f = sd / e
        for sign, word in ((-1, "-"), (1, "+")):
            k = 1 + sign * f
            out.append(Variant(f"{net.name} modulus {word}1 SD", k if law_from_modulus else 1.0,
                               k, source=f"{net.name} profile: E = {e / 1e9:.3g} +- "
                                         f"{sd / 1e9:.2g} GPa (measured)"))
    else:
        notes.append(f"{net.name} (net): no SD of the {source} modulus in its profile; "
                     "modulus spread not included (printgen calibrate writes sd_gpa)")
    if d.cables:
        out += _cable_variants(d, notes)
    if panel is not None and panel.has_geometry:
        out += _panel_geometry_variant(d, notes)
        out += _orientation_variants(d)
    opts = mounting_options() if d.cables else ()  # no border cables: bed and banks only
    nominal = mounting or (opts[0] if opts else None)
    out += [Variant(f"mounting: {m}", mounting=m, source="flume mounting option "
                    f"(nominal: {nominal})") for m in opts if m != nominal]
    if not opts:
        notes.append("mounting: the model scene has one mounting only; no mounting variant")
    out.append(Variant(f"initial slack {SLACK_MAX:.0%}", slack=SLACK_MAX,
                       source="printed net hung with 0 to 1 % slack (printgen; README: Uncertainty band)"))
    from printgen.verification.forms import model_form_variants

    out += model_form_variants(d, free_section, notes, nominal)
    return out, notes


def _cable_variants(d: Design, notes: list[str]) -> list[Variant]:
    mat = load_material(d.cables[0].material)
    e, source = mat.modulus()
    sd = mat.measured_modulus.sd if source == "measured" and mat.measured_modulus else None
    if not sd:
        notes.append(f"{mat.name} (cables): no SD of the {source} modulus in its profile; "
                     "modulus spread not included (printgen calibrate writes sd_gpa)")
        return []
    return [Variant(f"{mat.name} cable modulus {word}1 SD", cable_factor=1 + sign * sd / e,
                    source=f"{mat.name} profile: E = {e / 1e9:.3g} +- {sd / 1e9:.2g} GPa")
            for sign, word in ((-1, "-"), (1, "+"))]


def _panel_geometry_variant(d: Design, notes: list[str]) -> list[Variant]:
    """The panel law used without the rescaling from its (assumed) tested net to the design's."""
    mat = load_material(d.net.material)
    law, n = mat.panel_law, d.net
    tested = diamond_factor(law.mesh_along_load, law.mesh_across_load) * (
        law.strand_width * law.strand_thickness)
    design = get_pattern(n.pattern).membrane_factor(n.mesh_y_mm * MM, n.mesh_x_mm * MM) * \
        area_m2(n.strand)
    ratio = tested / design
    if abs(ratio - 1) < SAME:
        notes.append(f"{mat.name} panel law: the design's net is the tested net the profile "
                     "assumes, so the geometry assumption does not change the law")
        return []
    return [Variant(f"{mat.name} panel law: tested net = the design's net", net_factor=ratio,
                    source=f"{mat.name} profile [measured.panel_law] conditions")]


def _orientation_variants(d: Design) -> list[Variant]:
    """The panel law read along each mesh diagonal its profile does not record (the
    paper does not say which diagonal its printed panels were loaded along)."""
    from printgen.verification.scenes import ORIENTATIONS, recorded_orientation

    law = load_material(d.net.material).panel_law
    recorded = recorded_orientation(law)
    return [Variant(f"panel test along the {o} diagonal", orientation=o,
                    source=f"panel-test orientation not stated (profile: {recorded})")
            for o in ORIENTATIONS if o != recorded]


def model_load_kw(p: Prototype, d: Design, load: str | LoadCase | None = None
                  ) -> dict[str, Any]:
    """The model's load keywords for `sweep` under load case `load`, as `verify` loads it."""
    return load_keywords(p, d, load)[1]


def variant_scene(d: Design, v: Variant, coarsen: int = 1) -> BarrierScene:
    """The printed model's scene with variant `v`, on the design's mesh times `coarsen` (its
    strands `coarsen` times stiffer, so the membrane stiffness per unit width is kept)."""
    if coarsen != 1:
        n = d.net
        d = dataclasses.replace(d, net=dataclasses.replace(
            n, mesh_x_mm=n.mesh_x_mm * coarsen, mesh_y_mm=n.mesh_y_mm * coarsen))
    s = model_scene(d, **({"mounting": v.mounting} if v.mounting else {}),
                    orientation=v.orientation)
    laws = list(s.laws)
    if v.net_law == "derived":  # the virtual panel test's strand law
        from printgen.verification.forms import derived_net_law

        laws[0], how = derived_net_law(load_material(d.net.material), d.net, v.orientation)
        s = dataclasses.replace(s, assumptions=tuple(
            (w, f"{d.net.material}: {how}" if w == "net strands" else val, src)
            for w, val, src in s.assumptions))
    laws[0] = _scaled(laws[0], v.net_factor * coarsen)
    if len(laws) > 1:  # the printed border frame, of the net's material
        laws[1] = _scaled(laws[1], v.frame_factor)
    cables = {k: (nodes, _scaled(law, v.cable_factor)) for k, (nodes, law) in s.cables.items()}
    s = dataclasses.replace(s, laws=laws, cables=cables, pressure=v.pressure)
    if v.span is not None:  # the printed net mounted in the flume's free section
        from printgen.verification.mount import in_free_section

        s = in_free_section(s, v.span)
    from printgen.verification.forms import held_on_bed, routed

    s = held_on_bed(s) if v.bed == "held" else s
    return routed(s, v.routing)


def _scaled(law: tuple, factor: float) -> tuple:
    knees, slopes = law
    return tuple(knees), tuple(s * factor for s in slopes)


def effort(v: Variant, mounting: str | None = None) -> tuple[bool, ...]:
    """Sort key of variants (`mounting`: the nominal one), the longest sweep first: initial
    slack (a mechanism until its strands tighten), the net mounted in the flume's free section,
    another mounting, the virtual panel test's law, pressure normal to the net, the rest (CPU
    by bench timeline at 1:40: benchmarks/measurements.md#band-variant-order)."""
    return (v.slack == 0, v.span is None, v.mounting == mounting, v.net_law != "derived",
            v.pressure != "normal")


def run_variant(d: Design, v: Variant, lv: np.ndarray, coarsen: int = 1,
                load_kw: dict | None = None) -> Run:
    """Sweep the model with variant `v` (a worker job: module-level, picklable)."""
    return sweep(variant_scene(d, v, coarsen), lv, slack=v.slack, **(load_kw or {}))


def curves(run: Run) -> dict[str, np.ndarray]:
    """The run's normalised deformations, NaN at the levels that did not converge."""
    d = run.deformation
    bad = np.isin(d.levels, list(run.failed))
    return {k: np.where(bad, np.nan, d.values[k]) for k in METRICS}


@dataclass(frozen=True)
class Band:
    """The printed model's nominal curves and each variant's, on the design's own net.

    levels : (k,) h / h_B; nominal and variants[label] : METRICS key -> (k,), NaN where a
    sweep did not converge; coarsen : mesh multiplier the variants ran on (1: the design's
    net); refinement : multiplier -> largest change of a nominal curve, fraction of its peak.
    """

    levels: np.ndarray
    nominal: dict[str, np.ndarray]
    variants: dict[str, dict[str, np.ndarray]]
    sources: dict[str, str]
    notes: list[str]
    coarsen: int
    refinement: dict[int, float]
    seconds: float = 0.0
    failed: dict[str, list[float]] = field(default_factory=dict)
    mounting: str | None = None  # the nominal run's mounting, kept by every variant
    work: list[dict[str, Any]] = field(default_factory=list)  # Run.work() of every sweep run

    def envelope(self, *, from_start: bool = False
                 ) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
        """(min, max) over the nominal and every variant, per metric; `from_start` counts
        every curve from its value at h / h_B = 0 (what zeroed sensors read)."""
        lo, hi = {}, {}
        for key in METRICS:
            rows = [c[key] - (c[key][0] if from_start else 0.0)
                    for c in [self.nominal, *self.variants.values()]]
            stack = np.vstack(rows)
            lo[key], hi[key] = _nan_reduce(stack, np.nanmin), _nan_reduce(stack, np.nanmax)
        return lo, hi


def _nan_reduce(stack: np.ndarray, fn) -> np.ndarray:
    out = np.full(stack.shape[1], np.nan)
    ok = ~np.all(np.isnan(stack), axis=0)
    out[ok] = fn(stack[:, ok], axis=0)
    return out


def refinement_test(d: Design, nominal: dict[str, np.ndarray], lv: np.ndarray,
                    load_kw: dict | None = None, base: Variant | None = None,
                    work: list[dict[str, Any]] | None = None,
                    ahead: dict[int, Future] | None = None) -> tuple[int, dict[int, float]]:
    """Coarsest mesh multiplier whose nominal sweep stays within REFINE_TOL of `nominal` (the
    design's own net) on every metric, and each tried multiplier's largest change. The
    multipliers are tried from the finest: once one fails, coarser ones are not run. `work`
    gets each sweep's Run.work(). `ahead`: multiplier -> the sweep of `base` on it, started
    before `lv` was known (used when it ran at `lv`, else run again)."""
    best, change = 1, {}
    for k in COARSENINGS:
        if not meshable(d, k):
            break
        run = collect([ahead[k]])[0] if ahead and k in ahead else None
        if run is None or not np.array_equal(run.deformation.levels, lv):
            run = run_variant(d, base or Variant(), lv, k, load_kw)
        if work is not None:
            work.append(run.work())
        change[k] = _largest_change(curves(run), nominal)
        if change[k] >= REFINE_TOL:
            break
        best = k
    return best, change


def meshable(d: Design, k: int) -> bool:
    try:
        variant_scene(d, Variant(), k)
    except GeometryError:
        return False
    return True


def _largest_change(c: dict[str, np.ndarray], ref: dict[str, np.ndarray]) -> float:
    worst = 0.0
    for key in METRICS:
        peak = float(np.nanmax(np.abs(ref[key])))
        if peak > 0:
            diff = np.abs(c[key] - ref[key])
            worst = max(worst, float(np.nanmax(diff)) / peak if np.any(~np.isnan(diff)) else 0)
    return worst


def model_band(d: Design, nominal: Run, *, load_kw: dict | None = None,
               variants: list[Variant] | None = None, notes: list[str] | None = None,
               free_section: float | None = None, ahead: dict[int, Future] | None = None,
               then: Callable[[], object] | None = None) -> Band:
    """Sweep every variant of design `d` and collect them around the `nominal` run (the
    model's sweep on the design's own net, as `verify` ran it), at the same levels.

    The variants run on the coarsest net that passes the refinement test (`ahead`: its
    sweeps already started, `refinement_test`); there a variant's curve is the nominal plus
    the variant's change on the coarse net. `then` is called once the variants are started
    (within printgen.workers.shared_pool: to queue more jobs behind them).
    """
    t0 = time.perf_counter()
    lv = nominal.deformation.levels
    mounting = getattr(nominal.scene, "mounting", None)
    if variants is None:
        variants, auto_notes = model_variants(d, mounting, free_section)
        notes = [*(notes or []), *auto_notes]
    variants = [v if v.mounting else dataclasses.replace(v, mounting=mounting)
                for v in variants]
    nom = curves(nominal)
    work: list[dict[str, Any]] = []
    with span("band: refinement test"):
        k, change = refinement_test(d, nom, lv, load_kw, Variant(mounting=mounting), work,
                                    ahead)
    # longest first (the worker that takes the last job should not start a long one late)
    order = sorted(range(len(variants)), key=lambda i: effort(variants[i], mounting))
    jobs: list[tuple] = [(run_variant, (d, variants[i], lv, k, load_kw), {}) for i in order]
    if k > 1:
        jobs.append((run_variant, (d, Variant(mounting=mounting), lv, k, load_kw), {}))
    started = submit_jobs(jobs)
    if then is not None:
        then()
    done = collect(started)
    extra = done[len(variants):]  # the nominal on the coarse net, when k > 1
    base = curves(extra[0]) if extra else None
    runs = [done[order.index(i)] for i in range(len(variants))]
    recorded = sorted(range(len(variants)), key=lambda i: -variants[i].slack)  # report.json's
    work += [runs[i].work() for i in recorded] + [r.work() for r in extra]
    out, failed = {}, {}
    for v, r in zip(variants, runs, strict=True):
        c = curves(r)
        out[v.label] = c if base is None else {m: nom[m] + c[m] - base[m] for m in METRICS}
        if r.failed:
            failed[v.label] = sorted(r.failed)
    return Band(lv, nom, out, {v.label: v.source for v in variants}, list(notes or []), k,
                change, time.perf_counter() - t0, failed, mounting, work)


SIGNIFICANT = 0.1  # levels where the prototype is below 10 % of its peak carry no verdict
INSIDE = 1e-9  # relative round-off allowed at a band edge


@dataclass(frozen=True)
class BandVerdict:
    """Where the prototype's curve lies against the model band, for one metric.

    kind : "inside", "stiffer", "softer", "partly inside" or "crossing"; least, most :
    smallest and largest relative gap (fraction) where the prototype is outside the band.
    """

    metric: str
    kind: str
    least: float
    most: float
    inside_levels: int
    levels: int
    text: str


def band_verdict(metric: str, proto: np.ndarray, lo: np.ndarray, hi: np.ndarray
                 ) -> BandVerdict:
    """Compare the prototype's curve with the model band [lo, hi] at every level where the
    prototype reaches SIGNIFICANT of its peak. The model is "stiffer" where it deforms less
    than the prototype even in its softest variant; "stiffer by at least X %": its softest
    variant deforms at least X % less than the prototype at every such level ("softer by at
    least X %": its stiffest variant deforms at least X % more)."""
    p = np.asarray(proto, float)
    keep = ~np.isnan(p) & ~np.isnan(lo) & ~np.isnan(hi)
    peak = float(np.abs(p[keep]).max()) if keep.any() else 0.0
    keep &= np.abs(p) >= SIGNIFICANT * peak
    if peak == 0.0 or not keep.any():
        return BandVerdict(metric, "inside", 0.0, 0.0, 0, 0, "no deformation to compare")
    s = np.sign(p[keep])  # compare magnitudes: a negative curve flips the band
    pp, a, b = s * p[keep], s * lo[keep], s * hi[keep]
    low, high = np.minimum(a, b), np.maximum(a, b)
    tol = INSIDE * peak
    stiffer, softer = high < pp - tol, low > pp + tol
    gap_stiff = np.minimum(1 - high[stiffer] / pp[stiffer], 1.0)  # the model deforms less
    gap_soft = low[softer] / pp[softer] - 1  # the model deforms more
    n, inside = int(keep.sum()), int((~stiffer & ~softer).sum())
    if inside == n:
        kind, least, most = "inside", 0.0, 0.0
        text = "prototype inside the model band"
    elif stiffer.any() and softer.any():
        kind, least, most = "crossing", float(gap_stiff.max()), float(gap_soft.max())
        text = (f"the prototype crosses the model band: model stiffer by up to {least:.0%} "
                f"at some levels, softer by up to {most:.0%} at others")
    else:
        gaps, word = (gap_stiff, "stiffer") if stiffer.any() else (gap_soft, "softer")
        least, most = float(gaps.min()), float(gaps.max())
        if inside == 0:
            kind, text = word, f"model {word} by at least {least:.0%} (up to {most:.0%})"
        else:
            kind = "partly inside"
            text = (f"prototype inside the model band at {inside} of {n} levels; model "
                    f"{word} by up to {most:.0%} at the others")
    return BandVerdict(metric, kind, least, most, inside, n, text)


def band_verdicts(proto: dict[str, np.ndarray], band: Band, *, from_start: bool = False
                  ) -> list[BandVerdict]:
    """One verdict per metric: the prototype's curves (at the band's levels) vs the band."""
    lo, hi = band.envelope(from_start=from_start)
    out = []
    for key in METRICS:
        p = proto[key] - (proto[key][0] if from_start else 0.0)
        out.append(band_verdict(key, p, lo[key], hi[key]))
    return out
