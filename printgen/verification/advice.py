"""What to change when the verdict is not PASS: a change printgen has verified to pass, or a plain
statement that none exists within the bundled profiles and why.

The changes are tried cheapest first, every one re-checked with the solver before it is offered:

1. the sensors: when they pull more than their share of the model's water load
   (`printgen.verification.sensors`), the same net with each wire pulling the largest force that
   keeps the share at the threshold;
2. the net: the design search's space at this scale (material x strand section x diamond mesh,
   `printgen.search.space`), on a sub-grid of ADVICE_MESHES meshes each way with the design's
   own border, screened by the analytic membrane law (`printgen.search.screen`); the printable
   net of lowest membrane-law error of each material x section pair, those on the side the
   verdict asks for (softer when too stiff) spread in stiffness and bracketed (`bracketed`),
   are swept against the prototype's sweep the verification already made (never swept again),
   on the band's solver net (the coarsest whose nominal curves stay within the band's refinement
   tolerance: the design's own on both examples), warm-started level to level (a change on
   the design's own net, `same_net`, also from the design's own sweep at that level); a net
   that passes on a coarser net is confirmed on its own before it is named. When
   the sensors are too strong the nets are tried with the weaker sensors (with the strong ones
   no net can match: the sensors' pull is not similar).

The flume's limits are not advised here: a flume that cannot run the test is a capacity
statement needing no solve (the verdict's own fix). A candidate passes when every compared
quantity is within tolerance over the levels both barriers reached: the nominal comparison of the
verdict, not its band. The cost is bounded: one screen of a few thousand nets (about
SCREEN_RATE per second) and at most ADVICE_ROUNDS x ADVICE_NETS + 2 model sweeps
(`printgen.run.budget` counts them); past them the advice says what it tried and stops.

A net whose pattern is not the search's diamond keeps its pattern and mesh and changes its
strand (`same_mesh`): at a fixed pattern and mesh the membrane stiffness at small strain is
proportional to the strand's E A, by which the strands are ranked.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from printgen.barrier.loads import LoadCase
from printgen.errors import SolverError
from printgen.executor.local import run_jobs
from printgen.inputs.materials import load_material
from printgen.inputs.prototype import Prototype
from printgen.scaling.record import Design, Section
from printgen.scaling.section import area_m2
from printgen.scaling.selection import (
    CALIBRATE_FIRST,
    MIN_SAFETY_FACTOR,
    peak_strand_force,
    print_limits,
)
from printgen.scaling.similitude import scale_targets
from printgen.scene.options import SceneOptions, build_scene
from printgen.scene.scenes import lateral_mounting
from printgen.search.choice import SMALL_STRAIN_TOLERANCE, binding_constraints, describe
from printgen.search.nets import candidate_design, design_point
from printgen.search.screen import Screened, screen_batch
from printgen.search.space import NetPoint, SearchContext, default_space, grid, search_context
from printgen.units import MM
from printgen.verification.compare import METRICS, Mismatch, compare, headlines
from printgen.verification.preprint import (
    Run,
    States,
    from_states,
    load_keywords,
    sensor_force,
    sweep,
)

ADVICE_NETS = 4  # nets the advice sweeps per round (one pool batch on 2 cores)
ADVICE_ROUNDS = 2  # rounds: the spread over all candidates, then between the two that bracket
ADVICE_MESHES = 6  # mesh counts screened each way, evenly spread over the search's range
# nets the advice screens at most: 8 bundled materials x 2 beads x 5 layers x ADVICE_MESHES^2
# (with the design's own border), under a second at SCREEN_RATE
ADVICE_SCREEN = 8 * 2 * 5 * ADVICE_MESHES**2
SEARCHED_PATTERN = "diamond"  # the design search's nets (`printgen.search.space`)
NEXT_DESIGN = "next-design.json"  # the verified net, as `printgen make --design` reads it


@dataclass(frozen=True)
class Tried:
    """One change checked with the solver: what it is, whether it passes, its RMS mismatch
    (over the compared quantities, of the prototype's peak) and its verdict's sentences."""

    what: str
    passes: bool
    mismatch: float
    headline: str
    coarsen: int = 1
    stiff: tuple[str, ...] = ()  # quantities off because the model deforms less
    soft: tuple[str, ...] = ()  # quantities off because it deforms more

    def to_record(self) -> dict[str, Any]:
        return {"change": self.what, "passes": self.passes,
                "mismatch_rms": self.mismatch if math.isfinite(self.mismatch) else None,
                "headline": self.headline, "solver_net_coarsened": self.coarsen,
                "too_stiff": list(self.stiff), "too_soft": list(self.soft)}


@dataclass(frozen=True)
class Advice:
    """The advice of a run that did not pass: `change` (what to change, "" when no verified
    change exists), `design` (the verified net, written as NEXT_DESIGN; None when the change is
    not the net), `sensor_force_n` (the sensor force the change needs, None: the file's),
    `reason` (why no change passes: the binding constraint), `tried` (every change the solver
    checked), `screened` (nets screened), `seconds` (wall time)."""

    change: str
    design: Design | None
    sensor_force_n: float | None
    reason: str
    tried: tuple[Tried, ...]
    screened: int
    seconds: float = 0.0
    notes: tuple[str, ...] = field(default_factory=tuple)
    next: str = ""  # the "Next" line (`next_step`), set by the run that knows its files
    flume_table: bool = True  # the prototype file has a [flume] table to set the force in

    @property
    def found(self) -> bool:
        return bool(self.change)

    def next_step(self, prototype_file: str, scale: float, out: str | None) -> str:
        """The report's "Next" line: the change and the exact command that runs it, or the
        statement that none exists."""
        if not self.found:
            return ("No change printgen tried passes: " + self.reason + ". Change the "
                    "prototype's test (scale, sensors) or measure the materials "
                    "(printgen testpieces) before printing.")
        cmd = f"printgen make {prototype_file} -s {scale:g}"
        steps = []
        if self.sensor_force_n is not None:
            table = "" if self.flume_table else (
                " (add a [flume] table with your flume's width_m, max_discharge_l_per_s, "
                "froude_min and froude_max: the verdict then checks them too)")
            steps.append(f"set [flume] sensor_force_n = {self.sensor_force_n:.2g} in "
                         f"{prototype_file}{table}")
        if self.design is not None:
            where = f"{out}/{NEXT_DESIGN}" if out else NEXT_DESIGN
            cmd += f" --design {where} --out {out}-next" if out else f" --design {where}"
        steps.append(f"run {cmd}" + (f" ({out}: this output folder)"
                                     if out and self.design is not None else ""))
        text = (f"{self.change}; printgen verified that it passes with the nominal inputs "
                f"({self.tried_text()}; its band, which make sweeps, may still leave the "
                "verdict UNDECIDED). To apply it: " + ", then ".join(steps) + ".")
        return " ".join([text, *self.notes])

    def tried_text(self) -> str:
        ok = next(t for t in reversed(self.tried) if t.passes and t.what == self.change)
        return (f"every quantity within tolerance, RMS mismatch {ok.mismatch:.3f} of the "
                f"prototype's peak; {len(self.tried)} change(s) checked with the solver")

    def to_record(self) -> dict[str, Any]:
        return {"next": self.next, "change": self.change or None, "found": self.found,
                "design_file": NEXT_DESIGN if self.design is not None else None,
                "sensor_force_n": self.sensor_force_n, "reason": self.reason or None,
                "tried": list(self.tried), "screened": self.screened,
                "verified_at_most": ADVICE_NETS * ADVICE_ROUNDS, "notes": list(self.notes),
                "definition": ("a change passes when every compared quantity is within "
                               "tolerance against the prototype's sweep (the nominal "
                               "comparison of the verdict, not its band); nets screened by "
                               "the membrane law, the best verified with the solver")}


def weaker_force(limit_n: float) -> float:
    """The sensor force to use: the limit rounded down to two significant digits (the force
    the report states), so the share stays within its threshold."""
    digits = 1 - math.floor(math.log10(limit_n))
    return math.floor(limit_n * 10**digits) / 10**digits


def model_run(p: Prototype, d: Design, lv: np.ndarray, *, force: float, coarsen: int = 1,
              load: str | LoadCase | None = None, start: States | None = None) -> Run:
    """The model `d` swept at levels `lv` with each sensor pulling `force` N, on its net
    `coarsen` times coarser (a worker job: module-level, picklable); `start`: level -> the
    displacements of a net with the same nodes and supports (`same_net`), one more warm start
    at that level."""
    kw = load_keywords(p, d, load)[1]
    options = SceneOptions(mounting=lateral_mounting(p), load=kw["load"], sensor_force=force,
                           coarsen=coarsen)
    return sweep(build_scene(d, options), lv, guesses=from_states(start), **kw)


def same_net(d: Design, cand: Design, coarsen: int) -> bool:
    """Whether `cand`'s solver net has the nodes of `d`'s own, node for node (same pattern,
    mesh, border, frame and cables: only its strand, or its sensors' pull, differs), so that
    `d`'s converged state at a level is a start for it there. A start is only a start: the
    solver begins from the lowest potential of it and the path's own (`solver.solve_path`)
    and Newton converges to the same equilibrium within its tolerance."""
    a, b = d.net, cand.net
    keys = ("pattern", "width_mm", "height_mm", "mesh_x_mm", "mesh_y_mm", "border_width_mm",
            "wave")
    return (coarsen == 1 and d.cables == cand.cables
            and all(getattr(a, k) == getattr(b, k) for k in keys))


def _job(p: Prototype, d: Design, lv: np.ndarray, force: float, coarsen: int,
         load: str | LoadCase | None, start: States | None = None) -> Run | str:
    try:
        return model_run(p, d, lv, force=force, coarsen=coarsen, load=load, start=start)
    except SolverError as exc:  # a candidate the solver cannot follow does not pass
        return str(exc)


def against(proto: Run, run: Run | str, what: str, coarsen: int) -> Tried:
    """The change's run compared with the prototype's at the levels both reached."""
    if isinstance(run, str):
        return Tried(what, False, math.inf, f"the solver did not converge: {run}", coarsen)
    pd, md = proto.deformation, run.deformation
    keep = np.array([lv not in run.failed for lv in pd.levels])
    mm = compare(pd.only(keep), md.only(np.isin(md.levels, pd.levels[keep])))
    bad = [m for m in mm if not m.ok and math.isfinite(m.ratio_high)]
    return Tried(what, all(m.ok for m in mm), _rms(mm), "\n".join(headlines(mm)), coarsen,
                 tuple(m.metric for m in bad if m.ratio_high < 1),
                 tuple(m.metric for m in bad if m.ratio_high >= 1))


def _rms(mm: list[Mismatch]) -> float:
    return math.sqrt(sum(m.rms_rel**2 for m in mm) / len(mm)) if mm else math.inf


def screen_nets(p: Prototype, d: Design) -> tuple[SearchContext, list[Screened], Any]:
    """(context, screened nets, space) of the advice's sub-grid at the design's scale."""
    t = scale_targets(p, d.scale)
    space = default_space(p, t)
    ctx = search_context(p, t, space, printer=d.printer)
    if d.net.material not in space.materials:  # the design's own material is a candidate too
        ctx = dataclasses.replace(ctx, materials=ctx.materials + (
            load_material(d.net.material),))
        space = dataclasses.replace(space, materials=(*space.materials, d.net.material))
    own = design_point(ctx, d)
    border = own.border_beads if own.border_beads in space.border_beads \
        else space.border_beads[0]
    points = sub_grid(grid(ctx, space), border)
    return ctx, screen_batch(ctx, points), space


def sub_grid(points: list[NetPoint], border: int) -> list[NetPoint]:
    """The points with `border` on ADVICE_MESHES mesh counts each way, evenly spread."""
    xs = _spread(sorted({q.half_cells_x for q in points}))
    ys = _spread(sorted({q.half_cells_y for q in points}))
    return [q for q in points
            if q.border_beads == border and q.half_cells_x in xs and q.half_cells_y in ys]


def _spread(values: list[int]) -> set[int]:
    if len(values) <= ADVICE_MESHES:
        return set(values)
    picks = np.linspace(0, len(values) - 1, ADVICE_MESHES).round().astype(int)
    return {values[i] for i in picks}


def best_pairs(screened: list[Screened], way: str = "", own_n_per_m: float = 0.0
               ) -> list[Screened]:
    """The nets the solver checks: the printable net of lowest membrane-law error (across and
    up, 1-40 % strain) of each material x section pair; with `way` ("stiff": the design deforms
    too little, "soft": too much), only the pairs softer (stiffer) than the design's
    `own_n_per_m`, ADVICE_NETS of them spread evenly in log stiffness from the nearest to the
    farthest (deformation falls as stiffness rises: the spread brackets the tolerance window,
    and the farthest one tells whether any printable net reaches it); without, the ADVICE_NETS
    pairs of lowest error."""
    best: dict[tuple, Screened] = {}
    for s in screened:
        if not s.feasible:
            continue
        if way == "stiff" and not s.membrane_n_per_m < own_n_per_m:
            continue
        if way == "soft" and not s.membrane_n_per_m > own_n_per_m:
            continue
        pair = (s.point.material, s.point.beads_across, s.point.layers)
        if pair not in best or s.error_rms_log < best[pair].error_rms_log:
            best[pair] = s
    pool = list(best.values())
    if not way:
        return sorted(pool, key=lambda s: (s.error_rms_log, s.point.index))[:ADVICE_NETS]
    pool.sort(key=lambda s: (abs(math.log(s.membrane_n_per_m / own_n_per_m)), s.point.index))
    return pool


def spread(n: int, k: int = ADVICE_NETS) -> list[int]:
    """`k` indices of 0..n-1 spread evenly, both ends included (all when n <= k)."""
    if n <= k:
        return list(range(n))
    return sorted({int(i) for i in np.linspace(0, n - 1, k).round()})


def bracketed(n: int, way: str, check: Callable[[list[int]], list[Tried]]
              ) -> tuple[list[int], list[Tried]]:
    """Candidates 0..n-1 (ordered nearest to farthest from the design's stiffness) checked in
    at most ADVICE_ROUNDS rounds of ADVICE_NETS: the first spread over all of them; when none
    passes and one still errs only `way` next to one that no longer does, the second spread
    between those two (deformation is monotone in the net's stiffness, so the window lies
    there). Returns the indices checked, in order, and their results."""
    idx = spread(n)
    done = dict(zip(idx, check(idx), strict=True))
    for _ in range(ADVICE_ROUNDS - 1):
        if not way or any(t.passes for t in done.values()):
            break
        order = sorted(done)
        same = [_ways(done[i]) == {way} for i in order]
        inner: list[int] = []
        for a, b, sa, sb in zip(order, order[1:], same, same[1:], strict=False):
            if sa and not sb:
                inner = list(range(a + 1, b))
                break
        if not inner:
            break
        picked = [inner[i] for i in spread(len(inner))]
        done.update(zip(picked, check(picked), strict=True))
    order = sorted(done)
    return order, [done[i] for i in order]


def direction(mismatches: list[Mismatch]) -> str:
    """"stiff" when every quantity off is off because the model deforms too little, "soft"
    when too much, "" when both or none."""
    bad = [m for m in mismatches if not m.ok and math.isfinite(m.ratio_high)]
    if bad and all(m.ratio_high < 1 for m in bad):
        return "stiff"
    if bad and all(m.ratio_high >= 1 for m in bad):
        return "soft"
    return ""


def advise(p: Prototype, d: Design, proto: Run, *, sensors_too_strong: bool,
           sensor_limit_n: float | None, coarsen: int = 1,
           load: str | LoadCase | None = None, way: str = "",
           start: States | None = None) -> Advice:
    """The advice for design `d` that did not pass (`_advise`), stating whether the prototype
    file has a [flume] table to set a sensor force in."""
    a = _advise(p, d, proto, sensors_too_strong=sensors_too_strong,
                sensor_limit_n=sensor_limit_n, coarsen=coarsen, load=load, way=way,
                start=start)
    return dataclasses.replace(a, flume_table=p.flume is not None)


def _advise(p: Prototype, d: Design, proto: Run, *, sensors_too_strong: bool,
           sensor_limit_n: float | None, coarsen: int = 1,
           load: str | LoadCase | None = None, way: str = "",
           start: States | None = None) -> Advice:
    """The advice for design `d` that did not pass; `proto`: the verification's prototype
    sweep (compared levels only), shared by every change; `sensor_limit_n`: the largest sensor
    force within the sensors' share; `coarsen`: the band's solver net; `way`: the design's
    error (`direction` of its mismatches); `start`: the design's own model sweep's states
    (`Run.states`), a warm start for every change on the same net (`same_net`)."""
    t0 = time.perf_counter()
    lv = proto.deformation.levels
    force = sensor_force(p)
    weaker = weaker_force(sensor_limit_n) if sensors_too_strong and sensor_limit_n else None
    tried: list[Tried] = []
    if weaker is not None:  # the cheapest change first, alone: it needs no new print
        what = (f"keep the net and use weaker sensors: each wire pulling {weaker:.2g} N "
                f"instead of {force:.3g} N")
        tried.append(against(proto, _job(p, d, lv, weaker, 1, load, start), what, 1))
        if tried[0].passes:
            return Advice(what, None, weaker, "", tuple(tried), 0, time.perf_counter() - t0)
    if d.net.pattern != SEARCHED_PATTERN:  # the search's nets would be another structure
        return same_mesh(p, d, proto, tried, weaker, way, load, t0, start)
    ctx, screened, space = screen_nets(p, d)
    own = screen_batch(ctx, [design_point(ctx, d)])[0]
    pool = best_pairs(screened, way, own.membrane_n_per_m)
    net_force = weaker if weaker is not None else force
    with_sensors = "" if weaker is None else f", with each sensor wire pulling {weaker:.2g} N"
    named = {id(s): f"print {describe(s)} instead{with_sensors}" for s in pool}

    def check(idx: list[int]) -> list[Tried]:
        cands = [candidate_design(ctx, pool[i].point, d) for i in idx]
        runs = run_jobs([(_job, (p, c, lv, net_force, coarsen, load,
                                 start if same_net(d, c, coarsen) else None), {})
                         for c in cands])
        return [against(proto, r, named[id(pool[i])], coarsen)
                for i, r in zip(idx, runs, strict=True)]

    idx, nets = bracketed(len(pool), way, check)
    picks = [pool[i] for i in idx]
    tried += nets
    passing = sorted((t.mismatch, i) for i, t in enumerate(nets) if t.passes)
    for _, i in passing[:1]:
        s = picks[i]
        cand = candidate_design(ctx, s.point, d)
        if coarsen > 1:  # confirmed on its own net before it is named
            ok = against(proto, _job(p, cand, lv, net_force, 1, load,
                                     start if same_net(d, cand, 1) else None), named[id(s)], 1)
            tried.append(ok)
            if not ok.passes:
                break
        notes = ((f"Its {s.point.material.upper()} law rests on a DATASHEET value: "
                  f"{CALIBRATE_FIRST}",) if s.datasheet else ())
        return Advice(named[id(s)], cand, weaker, "", tuple(tried), len(screened),
                      time.perf_counter() - t0, notes)
    reason = why_none(screened, space, nets, picks, weaker is not None, way, own)
    return Advice("", None, None, reason, tuple(tried), len(screened),
                  time.perf_counter() - t0)


@dataclass(frozen=True)
class Strand:
    """A strand for the design's own pattern and mesh: material, section, E A (N) and whether
    its modulus is a datasheet value."""

    material: str
    section: Section
    ea_n: float
    datasheet: bool

    def text(self, pattern: str) -> str:
        n = len(self.section.layer_heights_mm)
        return (f"{self.material.upper()} strand of {self.section.beads_across} bead(s) x {n} "
                f"layer(s) on this design's {pattern} mesh")


def strands(p: Prototype, d: Design) -> list[Strand]:
    """Every printable strand of the search's materials and passes (`default_space`) that is
    strong enough (safety factor >= MIN_SAFETY_FACTOR at the overflow strand force) on the
    design's own pattern and mesh."""
    t = scale_targets(p, d.scale)
    space = default_space(p, t)
    ctx = search_context(p, t, space, printer=d.printer)
    names = dict.fromkeys((*space.materials, d.net.material))
    force = peak_strand_force(t, d.net.mesh_x_mm * MM, d.net.mesh_y_mm * MM, d.net.pattern)
    out = []
    for name in names:
        m = load_material(name)
        e, source = m.modulus()
        for beads in space.beads:
            for layers in space.layers:
                sec = Section(ctx.style.bead_width_mm, beads,
                              tuple(ctx.style.layer_heights_mm(layers)))
                _, reasons = print_limits(sec, m, ctx.printer, f"net {name}")
                if reasons or m.failure_stress()[0] * area_m2(sec) < MIN_SAFETY_FACTOR * force:
                    continue
                out.append(Strand(name, sec, e * area_m2(sec), source == "datasheet"))
    return out


def same_mesh(p: Prototype, d: Design, proto: Run, tried: list[Tried], weaker: float | None,
              way: str, load: str | LoadCase | None, t0: float, start: States | None = None
              ) -> Advice:
    """The advice for a net the design search does not hold (its pattern is not a diamond):
    the design's own pattern and mesh with another strand. At a fixed pattern and mesh the
    membrane stiffness at small strain is proportional to the strand's E A, so the strands
    are ranked by it: with `way`, ADVICE_NETS of those softer (stiffer) than the design's,
    spread evenly in log E A from the nearest to the farthest; without, the nearest."""
    own = load_material(d.net.material).modulus()[0] * area_m2(d.net.strand)
    pool = strands(p, d)
    if way:
        pool = [c for c in pool if (c.ea_n < own) == (way == "stiff") and c.ea_n != own]
    pool.sort(key=lambda c: abs(math.log(c.ea_n / own)))
    if not way:
        pool = pool[:ADVICE_NETS]
    force = weaker if weaker is not None else sensor_force(p)
    extra = "" if weaker is None else f", with each sensor wire pulling {weaker:.2g} N"

    def design_of(c: Strand) -> Design:
        return dataclasses.replace(d, net=dataclasses.replace(d.net, material=c.material,
                                                              strand=c.section))

    def check(idx: list[int]) -> list[Tried]:
        cands = [design_of(pool[i]) for i in idx]
        runs = run_jobs([(_job, (p, c, proto.deformation.levels, force, 1, load,
                                 start if same_net(d, c, 1) else None), {}) for c in cands])
        return [against(proto, r, f"print {pool[i].text(d.net.pattern)} instead{extra}", 1)
                for i, r in zip(idx, runs, strict=True)]

    idx, nets = bracketed(len(pool), way, check)
    picks = [pool[i] for i in idx]
    designs = [design_of(c) for c in picks]
    tried = [*tried, *nets]
    ok = sorted((t.mismatch, i) for i, t in enumerate(nets) if t.passes)
    if ok:
        i = ok[0][1]
        notes = ((f"Its {picks[i].material.upper()} modulus is a DATASHEET value: "
                  f"{CALIBRATE_FIRST}",) if picks[i].datasheet else ())
        return Advice(nets[i].what, designs[i], weaker, "", tuple(tried), len(pool),
                      time.perf_counter() - t0, notes)
    scope = (f"keeping this {d.net.pattern} net's mesh, the advice changed only its strand "
             "(printgen design searches the meshes too): of "
             f"{len(pool)} printable, strong enough strands")
    if not picks:
        other = "softer" if way == "stiff" else "stiffer"
        return Advice("", None, None, f"{scope}, none is {other} than this design's",
                      tuple(tried), 0, time.perf_counter() - t0)
    far, run = picks[-1], nets[-1]
    what = (f"the farthest, {far.text(d.net.pattern)} ({far.ea_n / own:.2g} x this design's "
            "E A)")
    if way and _ways(run) == {way}:
        need = "soft" if way == "stiff" else "stiff"
        reason = (f"{scope}, no printable strand is {need} enough: {what}, is still too {way}: "
                  + _short(run.headline))
    else:
        reason = (f"{scope}, {len(picks)} were swept (the advice sweeps at most "
                  f"{ADVICE_ROUNDS} rounds of {ADVICE_NETS}) and none passes; {what}: "
                  + _short(run.headline))
    return Advice("", None, None, reason, tuple(tried), len(pool), time.perf_counter() - t0)


def why_none(screened: list[Screened], space: Any, nets: list[Tried], picks: list[Screened],
             weaker: bool, way: str = "", own: Screened | None = None) -> str:
    """The binding constraint when no change passes: no printable net, none near the target
    stiffness (how far the closest is), or the nearest ones verified and failing."""
    closest, binding = binding_constraints(screened, space)
    n_ok = sum(s.feasible for s in screened)
    scope = (f"of {len(screened)} nets screened at this scale in the bundled profiles "
             f"({n_ok} printable), ")
    if closest is None:
        return scope + "none is printable: " + "; ".join(binding)
    c = next(s for s in screened if s.point.index == closest)
    if way and own is not None and picks:  # the nets checked span one side of the design
        far, run, ways = picks[-1], nets[-1], _ways(nets[-1])
        most = "softest" if way == "stiff" else "stiffest"
        ratio = far.membrane_n_per_m / own.membrane_n_per_m
        sensors = ", with weaker sensors," if weaker else ","
        named = (f"the {most} printable net the solver checked{sensors} {describe(far)} "
                 f"({ratio:.2g} x this design's membrane stiffness, {1 + far.error_small:.2g} x "
                 "the target)")
        if ways == {way}:
            need = "soft" if way == "stiff" else "stiff"
            return (scope + f"no printable net is {need} enough: {named}, is still too {way}: "
                    + _short(run.headline))
        if len(ways) == 2:
            return (scope + f"{named} is too stiff in {_names(set(run.stiff))} and too soft in "
                    f"{_names(set(run.soft))} at once: a softer or stiffer net moves both the "
                    "same way, so no net stiffness fixes both (the border cables, the frame or "
                    "the load path differ)")
        return (scope + f"the {len(nets)} nets checked (the advice sweeps at most "
                f"{ADVICE_NETS}) bracket the prototype, from too {way} to {named}, too "
                f"{next(iter(ways))}, but none lies within tolerance; printgen design "
                "(--objective deformation) searches between them")
    if binding:  # no printable net within the small-strain tolerance
        way = "soft" if c.error_small > 0 else "stiff"
        return (scope + f"no profile is {way} enough: the closest to the target, "
                f"{describe(c)}, is {1 + c.error_small:.2g} x the target membrane stiffness "
                f"(on target: within +-{SMALL_STRAIN_TOLERANCE:.0%}); "
                + "; ".join(binding))
    best = min(zip(nets, picks, strict=True), key=lambda ns: ns[0].mismatch)
    sensors = " with weaker sensors" if weaker else ""
    out = (scope + f"the {len(nets)} of lowest membrane-law error (the advice sweeps at most "
           f"{ADVICE_NETS}) were swept{sensors} and none passes; the best, "
           f"{describe(best[1])}, still fails: " + _short(best[0].headline))
    stiff, soft = set(best[0].stiff), set(best[0].soft)
    if stiff and soft:  # a softer net deforms more everywhere: it cannot fix both at once
        out += (f"; it is too stiff in {_names(stiff)} and too soft in {_names(soft)} at "
                "once: a softer or stiffer net moves both the same way, so no net stiffness "
                "fixes both (the border cables, the frame or the load path differ)")
    return out


def _ways(t: Tried) -> set[str]:
    return {w for w, off in (("stiff", t.stiff), ("soft", t.soft)) if off}


def _target(c: Screened) -> str:
    """The printable net closest to the target membrane stiffness, as the screen rates it."""
    return (f"the closest to the target membrane stiffness at small strain is {describe(c)} "
            f"({c.error_small:+.0%})")


def _short(headline: str) -> str:
    """The verdict's sentences on one line, without the tolerance each repeats."""
    return "; ".join(h.split(" (off by")[0] for h in headline.split("\n"))


def _names(metrics: set[str]) -> str:
    return ", ".join(METRICS[m].split(" (")[0] for m in METRICS if m in metrics)
