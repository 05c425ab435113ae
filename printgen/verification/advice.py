"""What to change when the verdict is not PASS: a change printgen has verified to pass, or a plain
statement that none exists within the bundled profiles and why.

The changes are tried cheapest first, every one re-checked with the solver before it is offered:

1. the sensors: when they pull more than their share of the model's water load
   (`printgen.verification.sensors`), the same net with each wire pulling the largest force that
   keeps the share at the threshold;
2. the net: the design search's space at this scale (material x strand section x diamond mesh,
   `printgen.search.space`), on a sub-grid of ADVICE_MESHES meshes each way with the design's
   own border, screened by the analytic membrane law (`printgen.search.screen`); the printable
   net of lowest membrane-law error of each material x section pair, the ADVICE_NETS best pairs,
   are swept against the prototype's sweep the verification already made (never swept again),
   on the band's solver net (the coarsest whose nominal curves stay within the band's refinement
   tolerance); a net that passes there is confirmed on its own net before it is named. When
   the sensors are too strong the nets are tried with the weaker sensors (with the strong ones
   no net can match: the sensors' pull is not similar).

The flume's limits are not advised here: a flume that cannot run the test is a capacity
statement needing no solve (the verdict's own fix). A candidate passes when every compared
quantity is within tolerance over the levels both barriers reached: the nominal comparison of the
verdict, not its band. The cost is bounded: one screen of a few thousand nets (about
SCREEN_RATE per second) and at most ADVICE_NETS + 2 model sweeps (`printgen.run.budget` counts
them).
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from printgen.barrier.loads import LoadCase
from printgen.errors import SolverError
from printgen.executor.local import run_jobs
from printgen.inputs.materials import load_material
from printgen.inputs.prototype import Prototype
from printgen.scaling.record import Design
from printgen.scaling.selection import CALIBRATE_FIRST
from printgen.scaling.similitude import scale_targets
from printgen.scene.options import SceneOptions, build_scene
from printgen.scene.scenes import lateral_mounting
from printgen.search.choice import SMALL_STRAIN_TOLERANCE, binding_constraints, describe
from printgen.search.nets import candidate_design, design_point
from printgen.search.screen import Screened, screen_batch
from printgen.search.space import NetPoint, SearchContext, default_space, grid, search_context
from printgen.verification.compare import METRICS, Mismatch, compare, headlines
from printgen.verification.preprint import Run, load_keywords, sensor_force, sweep

ADVICE_NETS = 4  # nets the advice sweeps with the solver at most (one pool batch on 2 cores)
# the nets are swept on a net this many times coarser (strands as many times stiffer: the
# band's coarsening), about 4 x cheaper; a net that passes there is confirmed on its own
ADVICE_COARSEN = 2
ADVICE_MESHES = 6  # mesh counts screened each way, evenly spread over the search's range
# nets the advice screens at most: 8 bundled materials x 2 beads x 5 layers x ADVICE_MESHES^2
# (with the design's own border), under a second at SCREEN_RATE
ADVICE_SCREEN = 8 * 2 * 5 * ADVICE_MESHES**2
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
        return {"change": self.what, "passes": self.passes, "mismatch_rms": self.mismatch,
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
            steps.append(f"set [flume] sensor_force_n = {self.sensor_force_n:.2g} in "
                         f"{prototype_file}")
        if self.design is not None:
            where = f"{out}/{NEXT_DESIGN}" if out else NEXT_DESIGN
            cmd += f" --design {where} --out {out}-next" if out else f" --design {where}"
        steps.append(f"run {cmd}")
        text = (f"{self.change}; printgen verified that it passes "
                f"({self.tried_text()}). To apply it: " + ", then ".join(steps) + ".")
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
                "verified_at_most": ADVICE_NETS, "notes": list(self.notes),
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
              load: str | LoadCase | None = None) -> Run:
    """The model `d` swept at levels `lv` with each sensor pulling `force` N, on its net
    `coarsen` times coarser (a worker job: module-level, picklable)."""
    kw = load_keywords(p, d, load)[1]
    options = SceneOptions(mounting=lateral_mounting(p), load=kw["load"], sensor_force=force,
                           coarsen=coarsen)
    return sweep(build_scene(d, options), lv, **kw)


def _job(p: Prototype, d: Design, lv: np.ndarray, force: float, coarsen: int,
         load: str | LoadCase | None) -> Run | str:
    try:
        return model_run(p, d, lv, force=force, coarsen=coarsen, load=load)
    except SolverError as exc:  # a candidate the solver cannot follow does not pass
        return str(exc)


def against(proto: Run, run: Run | str, what: str, coarsen: int) -> Tried:
    """The change's run compared with the prototype's at the levels both reached."""
    if isinstance(run, str):
        return Tried(what, False, math.inf, f"the solver did not converge: {run}", coarsen)
    pd, md = proto.deformation, run.deformation
    keep = np.array([lv not in run.failed for lv in pd.levels])
    mm = compare(_only(pd, keep), _only(md, np.isin(md.levels, pd.levels[keep])))
    bad = [m for m in mm if not m.ok and math.isfinite(m.ratio_high)]
    return Tried(what, all(m.ok for m in mm), _rms(mm), "\n".join(headlines(mm)), coarsen,
                 tuple(m.metric for m in bad if m.ratio_high < 1),
                 tuple(m.metric for m in bad if m.ratio_high >= 1))


def _only(d: Any, keep: np.ndarray) -> Any:
    return dataclasses.replace(d, levels=d.levels[keep],
                               values={k: v[keep] for k, v in d.values.items()},
                               max_strand_tension=d.max_strand_tension[keep],
                               max_cable_tension=d.max_cable_tension[keep])


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


def best_pairs(screened: list[Screened]) -> list[Screened]:
    """The printable net of lowest membrane-law error (across and up, 1-40 % strain) of each
    material x section pair, the ADVICE_NETS best pairs, best first."""
    best: dict[tuple, Screened] = {}
    for s in screened:
        if not s.feasible:
            continue
        pair = (s.point.material, s.point.beads_across, s.point.layers)
        if pair not in best or s.error_rms_log < best[pair].error_rms_log:
            best[pair] = s
    return sorted(best.values(), key=lambda s: (s.error_rms_log, s.point.index))[:ADVICE_NETS]


def advise(p: Prototype, d: Design, proto: Run, *, sensors_too_strong: bool,
           sensor_limit_n: float | None, coarsen: int = ADVICE_COARSEN,
           load: str | LoadCase | None = None) -> Advice:
    """The advice for design `d` that did not pass; `proto`: the verification's prototype
    sweep (compared levels only), shared by every change; `sensor_limit_n`: the largest sensor
    force within the sensors' share; `coarsen`: the band's solver net."""
    t0 = time.perf_counter()
    lv = proto.deformation.levels
    force = sensor_force(p)
    weaker = weaker_force(sensor_limit_n) if sensors_too_strong and sensor_limit_n else None
    tried: list[Tried] = []
    if weaker is not None:  # the cheapest change first, alone: it needs no new print
        what = (f"keep the net and use weaker sensors: each wire pulling {weaker:.2g} N "
                f"instead of {force:.3g} N")
        tried.append(against(proto, _job(p, d, lv, weaker, 1, load), what, 1))
        if tried[0].passes:
            return Advice(what, None, weaker, "", tuple(tried), 0, time.perf_counter() - t0)
    ctx, screened, space = screen_nets(p, d)
    picks = best_pairs(screened)
    net_force = weaker if weaker is not None else force
    runs = run_jobs([(_job, (p, candidate_design(ctx, s.point, d), lv, net_force, coarsen,
                             load), {}) for s in picks])
    with_sensors = "" if weaker is None else f", with each sensor wire pulling {weaker:.2g} N"
    named = {id(s): f"print {describe(s)} instead{with_sensors}" for s in picks}
    nets = [against(proto, r, named[id(s)], coarsen) for s, r in zip(picks, runs, strict=True)]
    tried += nets
    passing = sorted((t.mismatch, i) for i, t in enumerate(nets) if t.passes)
    for _, i in passing[:1]:
        s = picks[i]
        cand = candidate_design(ctx, s.point, d)
        if coarsen > 1:  # confirmed on its own net before it is named
            ok = against(proto, _job(p, cand, lv, net_force, 1, load), named[id(s)], 1)
            tried.append(ok)
            if not ok.passes:
                break
        notes = ((f"Its {s.point.material.upper()} law rests on a DATASHEET value: "
                  f"{CALIBRATE_FIRST}",) if s.datasheet else ())
        return Advice(named[id(s)], cand, weaker, "", tuple(tried), len(screened),
                      time.perf_counter() - t0, notes)
    reason = why_none(screened, space, nets, picks, weaker is not None)
    return Advice("", None, None, reason, tuple(tried), len(screened),
                  time.perf_counter() - t0)


def why_none(screened: list[Screened], space: Any, nets: list[Tried], picks: list[Screened],
             weaker: bool) -> str:
    """The binding constraint when no change passes: no printable net, none near the target
    stiffness (how far the closest is), or the nearest ones verified and failing."""
    closest, binding = binding_constraints(screened, space)
    n_ok = sum(s.feasible for s in screened)
    scope = (f"of {len(screened)} nets screened at this scale in the bundled profiles "
             f"({n_ok} printable), ")
    if closest is None:
        return scope + "none is printable: " + "; ".join(binding)
    c = next(s for s in screened if s.point.index == closest)
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
    stiff = set.intersection(*(set(n.stiff) for n in nets)) if nets else set()
    soft = set.intersection(*(set(n.soft) for n in nets)) if nets else set()
    if stiff and soft:  # a softer net deforms more everywhere: it cannot fix both at once
        out += (f"; every net swept is too stiff in {_names(stiff)} and too soft in "
                f"{_names(soft)} at once: a softer or stiffer net moves both the same way, so "
                "the net alone cannot fix them (the border cables, the frame or the load "
                "path differ)")
    return out


def _short(headline: str) -> str:
    """The verdict's sentences on one line, without the tolerance each repeats."""
    return "; ".join(h.split(" (off by")[0] for h in headline.split("\n"))


def _names(metrics: set[str]) -> str:
    return ", ".join(METRICS[m].split(" (")[0] for m in METRICS if m in metrics)
