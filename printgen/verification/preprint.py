"""Pre-print verification: the prototype and the printed model, each as a tension-only net
(`printgen.scene.scenes`), loaded hydrostatically from h / h_B = 0 to 1.1 (the reference's loading
test: water raised behind a folded film), or another load case of `printgen.barrier.loads` (flow,
drag, jam: a case may bring its own levels and states what it used at each), and compared by their
normalised deformations over the whole range (printgen.verification.compare). Also the
counter-example the report warns about: the simple barrier with steel at every scale.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from printgen import solver
from printgen.barrier.loads import OVERFLOW, LoadCase, Site, get_load
from printgen.errors import SolverError
from printgen.executor.local import (  # worker lifecycle: ground floor
    check_deadline,
    report_progress,
    run_jobs,
)
from printgen.inputs.prototype import Prototype
from printgen.outputs.display import Shown, Summary
from printgen.scaling.record import Design
from printgen.scaling.similitude import FlowCheck, scale_targets
from printgen.scene.options import SceneOptions, build_scene
from printgen.scene.pressure import loads_function
from printgen.scene.scenes import SENSOR_FORCE_N, BarrierScene, lateral_mounting, noted
from printgen.scene.solvernet import build, hold_share, wire_slack
from printgen.solver.driver import path_backend as backend_of_path
from printgen.solver.loads import total_forces
from printgen.units import MM
from printgen.verification.compare import (
    Deformation,
    Mismatch,
    compare,
    deformation,
    explain,
    headlines,
    increments,
)
from printgen.verification.sensors import (
    SensorCheck,
    needs_loaded_prototype,
    scene_sensor_force,
    sensor_check,
)

if TYPE_CHECKING:  # pragma: no cover
    from printgen.verification.bands import Band
    from printgen.verification.cases import CaseRuns
    from printgen.verification.decide import Decision

LEVEL_STEP = 0.05  # relative loading step of the sweep: at most 0.05, fine enough for every curve
PATH_CUTS = 2  # halvings tried before a load level is reported as not converged
MIN_COMPARED = 2  # levels both barriers must reach (h = 0 and one loaded) for a verdict
SHAPE_LEVELS = (0.5, 1.0, OVERFLOW)  # relative loadings whose deformed shapes are kept
SHAPE_DECIMALS = 6  # node positions in report.json rounded to 1 um: reproducible bytes
SOLVER_TOL = 1e-7  # out-of-balance force / load: far below what a flume measures (~1e-2)


def levels(step: float = LEVEL_STEP, top: float = OVERFLOW) -> np.ndarray:
    """0, step, ..., top (inclusive)."""
    n = round(top / step)
    return np.round(np.linspace(0.0, top, n + 1), 10)


def free_section(p: Prototype) -> float | None:
    """The flume's free section (m) of the prototype file's [flume] table, or None."""
    return p.flume.free_section if p.flume is not None else None


def sensor_force(p: Prototype) -> float:
    """The pull (N) of each sensor wire on the model: [flume] sensor_force_n, else the
    paper's SENSOR_FORCE_N."""
    return p.flume.sensor_force if p.flume is not None else SENSOR_FORCE_N


def load_keywords(p: Prototype, d: Design, load: str | LoadCase | None = None
                  ) -> tuple[dict[str, Any], dict[str, Any]]:
    """`sweep`'s load keywords of the prototype and of the model under `load`: the case and
    each barrier's site, the model's flow velocity its similitude target (v / sqrt(lambda))."""
    case = get_load(load)
    width = free_section(p)  # the flume's, m
    proto = Site(p.velocity, p.net.strand_diameter, p.depth,
                 None if width is None else width * d.scale)
    model = Site(scale_targets(p, d.scale)["velocity"], d.net.strand.width_mm * MM,
                 p.depth / d.scale, width, d.scale)
    return {"load": case, "site": proto}, {"load": case, "site": model}


@dataclass(frozen=True)
class Run:
    """One barrier's sweep: its deformation and solver statistics; `shapes`: node positions
    (n, 3) m at the SHAPE_LEVELS it reached; `hold_share`: the largest force of the hold of
    unloaded nodes over the applied load (0 without a hold); `backend`: the solver's linear
    backend(s) ("ldl", "cholmod", "pardiso", "lu"; comma-separated if several); `unknowns`:
    the solver net's free degrees of freedom; `cpu_s`: the sweep's CPU time in its process."""

    scene: BarrierScene
    deformation: Deformation
    iterations: list[int]
    seconds: float
    failed: dict[float, str]  # load levels that did not converge -> the solver's reason
    shapes: dict[float, np.ndarray] = field(default_factory=dict)
    hold_share: float = 0.0
    backend: str = ""
    unknowns: int = 0
    cpu_s: float = 0.0
    states: dict[float, np.ndarray] = field(default_factory=dict)  # kept on request: `sweep`

    def work(self) -> dict[str, Any]:
        """What the solver did (printgen.run.budget.counted_work): the net's unknowns, the
        load levels, the Newton iterations (chord steps included) and, under "time_s" (a
        volatile key: timings.json), the CPU seconds."""
        return {"name": self.scene.name, "unknowns": self.unknowns,
                "levels": len(self.iterations), "iterations": int(sum(self.iterations)),
                "time_s": self.cpu_s}

    def shape_record(self) -> dict[str, Any]:
        """The node positions (m, rounded to SHAPE_DECIMALS) at rest and at each kept level."""
        return {"units": "m", "decimals": SHAPE_DECIMALS,
                "node_order": "the design's net graph (NetDesign.graph, by its pattern)",
                "rest": np.round(self.scene.nodes, SHAPE_DECIMALS) + 0.0,
                "levels": {f"{lv:g}": np.round(x, SHAPE_DECIMALS) + 0.0
                           for lv, x in sorted(self.shapes.items())}}


def sweep(s: BarrierScene, lv: np.ndarray, *, slack: float = 0.0,
          guesses: Callable[[float], list[np.ndarray]] | None = None, keep_states: bool = False,
          paths: Callable[[float], list[np.ndarray | None]] | None = None,
          **load_kw: Any) -> Run:
    """Solve the load path (`load_kw`: the load case and site of `loads_function`); levels
    that do not converge are kept in `Run.failed` (left out of the comparison); SolverError
    only when fewer than MIN_COMPARED levels converge. `guesses`: more warm starts per level,
    `paths`: other nets' converged paths, shifted onto this one as starts (`solver.solve_path`);
    `keep_states`: keep each converged level's displacements (m, every solver node) in
    `Run.states`, a warm start for a similar net. The linear backend is a load path's
    (`solver.driver.path_backend`: a sweep factorizes its net tens to hundreds of times, so
    CHOLMOD's analysis pays back from smaller nets than in a single solve)."""
    t0, cpu0 = time.perf_counter(), time.process_time()
    net, ex = build(s, slack=slack)
    loads_at = loads_function(s, **load_kw)
    unknowns = int((~net.fixed_dofs).sum())

    def tracked(r: float) -> list:  # one progress report per load level tried
        check_deadline(f"{s.name}'s load sweep at h/h_B = {float(r):.3g}")
        report_progress(s.name, float(r), float(lv[-1]))
        return loads_at(r)

    results = solver.solve_path(net, tracked, lv, tol=SOLVER_TOL, max_cuts=PATH_CUTS,
                                skip_failed=True, guesses=guesses, paths=paths,
                                backend=backend_of_path(unknowns))
    failed = {float(r.level): r.reason for r in results if not r.converged}
    if len(lv) - len(failed) < min(MIN_COMPARED, len(lv)):
        raise SolverError(f"{s.name}: {len(failed)} of {len(lv)} load levels did not converge, "
                          f"nothing to compare; first: {next(iter(failed.values()))}")
    loose = [float(r.level) for r in results if r.converged and wire_slack(r.strains, ex)]
    if loose:  # a segment shorter than its knee would pull harder than the sensor
        raise SolverError(f"{s.name}: its sensor wires ({scene_sensor_force(s):.3g} N each) pull "
                          f"the net so far at h/h_B = {loose[0]:g} that a wire folds back over "
                          "its nodes (a "
                          "segment shorter than 3/8 of its length): the sensors are too strong "
                          "for this net; lower [flume] sensor_force_n in the prototype file, or "
                          "print a stiffer net")
    n, m, c = ex.n_nodes, ex.n_elements, ex.n_cables
    d = deformation(s, lv, [r.positions[:n] for r in results],
                    [r.tensions[:m] for r in results], [r.cable_tensions[:c] for r in results])
    share = 0.0
    for r in results:
        applied = float(np.abs(total_forces(loads_at(float(r.level)), r.positions)[0]).sum())
        share = max(share, hold_share(r.positions, r.tensions, ex, applied))
    shapes = {float(r.level): r.positions[:n] for r in results
              if r.converged and np.any(np.isclose(r.level, SHAPE_LEVELS))}
    return Run(s, d, [r.iterations for r in results], time.perf_counter() - t0, failed, shapes,
               share, ",".join(sorted({r.backend for r in results})),
               unknowns, time.process_time() - cpu0,
               {float(x): r.displacements for x, r in zip(lv, results, strict=False)
                if r.converged} if keep_states else {})  # a path stopped early is shorter


States = dict[float, np.ndarray]  # level -> displacements (m, every solver node): Run.states


def from_states(start: States | None) -> Callable[[float], list[np.ndarray]] | None:
    """`sweep`'s `guesses` from another run's `Run.states`: its state at the same level (None:
    no start given)."""
    if not start:
        return None

    def at(level: float) -> list[np.ndarray]:
        u = start.get(float(level))
        return [] if u is None else [u]

    return at


@dataclass(frozen=True, repr=False)
class Verification(Shown):
    """Prototype vs printed model over the loading sweep; `flow`: the model flow at this
    scale, with the limits of the flume that bind the verdict (None: not checked). Shown
    (repr, notebook) by its verdict and mismatches; its curves by `curves_table`."""

    load_case: str
    prototype: Run
    model: Run
    mismatches: list[Mismatch]
    reasons: list[str]
    counterexample: CounterExample | None = None
    from_start: list[Mismatch] | None = None  # the same, counted from h / h_B = 0
    asked: int = 0  # load levels asked; the comparison used len(model.deformation.levels)
    load: dict[str, Any] = field(default_factory=dict)  # the case's spec and per-level values
    by_load: dict[str, CaseRuns] = field(default_factory=dict)  # --loads: each case's sweeps
    flow: FlowCheck | None = None
    sensors: SensorCheck | None = None  # the sensors' share of the load (and its check)
    loaded_prototype: Run | None = None  # the prototype swept with sensors scaled (sensors)
    decision: Decision | None = None  # the bands' three-valued verdict (decide.decide)
    prototype_band: Band | None = None  # the prototype's variants (bands.prototype_band)

    @property
    def ok(self) -> bool:
        """True when the model deforms like the prototype (every quantity within tolerance);
        the verdict also needs a flume that can run the test (`verdict`)."""
        return all(m.ok for m in self.mismatches)

    @property
    def runnable(self) -> bool:
        """False when the prototype file's flume cannot run the scaled test (its discharge,
        width or Froude range: `printgen.scaling.flow`)."""
        return self.flow is None or not self.flow.limits

    @property
    def verdict(self) -> str:
        """FAIL when the flume cannot run the test; else the bands' verdict (`decision`:
        PASS, FAIL or UNDECIDED when the model's and the prototype's central bands straddle
        the tolerance); without bands, PASS when the nominal model deforms like the
        prototype."""
        if not self.runnable:
            return "FAIL"
        if self.decision is not None:
            return self.decision.verdict
        return "PASS" if self.ok else "FAIL"

    @property
    def compared(self) -> int:
        """Load levels where both barriers converged (the comparison's levels)."""
        return len(self.model.deformation.levels)

    @property
    def complete(self) -> bool:
        """True when the verdict rests on every level asked (no level left out)."""
        return self.compared >= self.asked

    @property
    def sensors_to_blame(self) -> bool:
        """True when the model fails only because its sensors pull too hard at this scale
        (it matches a prototype whose sensors pull as much of its load)."""
        s = self.sensors
        return not self.ok and s is not None and s.too_strong and s.net_similar

    @property
    def headlines(self) -> list[str]:
        """The verdict's sentences: each flume limit that binds, then the deformations' (one
        per direction of error: `printgen.verification.compare.headlines`), or the sensors'
        when they are what is off."""
        flume = [] if self.flow is None else [f"the flume cannot run this test: {lim.text}"
                                              for lim in self.flow.limits]
        if self.sensors_to_blame:
            assert self.sensors is not None
            return [*flume, self.sensors.text()]
        own = headlines(self.mismatches)
        if self.runnable and self.decision is not None and self.decision.sentence():
            return [self.decision.sentence(), *(f"with the nominal inputs: {x}" for x in own)]
        return flume + own

    @property
    def headline(self) -> str:
        """The verdict's sentences, one per line."""
        return "\n".join(self.headlines)

    def summary(self) -> Summary:
        from printgen.verification.tables import verification_summary

        return verification_summary(self)

    def curve_rows(self, band: Band | None = None) -> list[dict[str, float]]:
        """The curves, one dict per relative loading (`printgen.verification.tables`)."""
        from printgen.verification.tables import curve_rows

        return curve_rows(self, band)

    def curves_table(self, band: Band | None = None) -> Any:
        """The curves as a pandas DataFrame (the `table` extra): one row per h / h_B,
        strains in % (`_pct`), deflection and lowering normalised, tensions in N or kN, the
        `band`'s min and max when given."""
        from printgen.outputs.display import frame

        return frame(self.curve_rows(band), "the verification curves")

    def to_record(self) -> dict[str, Any]:
        """Every number of the verification, JSON-ready."""
        def dump(d: Deformation) -> dict[str, Any]:
            return {"levels": d.levels, "values": d.values,
                    "max_strand_tension_n": d.max_strand_tension,
                    "max_cable_tension_n": d.max_cable_tension}

        runs = (("prototype", self.prototype), ("model", self.model))
        return {
            "load_case": self.load_case, "ok": self.ok, "verdict": self.verdict,
            "summary": self.headline,
            "flume": {"limits": [] if self.flow is None else list(self.flow.limits),
                      "fix": "" if self.flow is None else self.flow.fix},
            "reasons": self.reasons, "mismatches": self.mismatches,
            "mismatches_from_start": self.from_start,
            "prototype": dump(self.prototype.deformation), "model": dump(self.model.deformation),
            "iterations": {who: run.iterations for who, run in runs},
            "solver_backend": {who: run.backend for who, run in runs},
            "not_converged": {who: run.failed for who, run in runs},
            "levels_asked": self.asked, "levels_compared": self.compared,
            "complete": self.complete,
            "counterexample": self.counterexample,
            "mounting": self.model.scene.mounting,
            "hold_share": {who: run.hold_share for who, run in runs},
            "deformed_shape": self.model.shape_record(),
            "load": self.load,
            "sensors": None if self.sensors is None else self.sensors.to_record(),
            "decision": None if self.decision is None else self.decision.to_record(),
            "by_load": {name: c.to_record() for name, c in self.by_load.items()},
            "assumptions": {who: [dict(zip(("what", "value", "source"), a, strict=True))
                                  for a in run.scene.assumptions] for who, run in runs},
        }


def barriers(p: Prototype, d: Design, load: str | LoadCase | None, mounting: str | None,
             prototype: BarrierScene | None = None
             ) -> tuple[LoadCase, dict[str, Any], dict[str, Any], BarrierScene, BarrierScene]:
    """(the load case, the prototype's and the model's sweep keywords, their scenes), both
    mounted by `mounting` (default: the prototype file's [flume] lateral); `prototype`: the
    prototype's scene when the caller built it already (it does not depend on the design)."""
    mounting = mounting or lateral_mounting(p)
    kw_p, kw_m = load_keywords(p, d, load)
    case = kw_m["load"]
    options = SceneOptions(mounting=mounting, load=case)
    model = dataclasses.replace(options, sensor_force=sensor_force(p))
    ps = prototype if prototype is not None else build_scene(p, options)
    return case, kw_p, kw_m, ps, build_scene(d, model)


@dataclass(frozen=True)
class VerifyPlan:
    """What `verify` sweeps: the load case, the prototype's and the model's sweep keywords and
    scenes, the load levels; `jobs` starts the two sweeps (model first: the longer one),
    `verified` compares what they gave."""

    case: LoadCase
    kw_p: dict[str, Any]
    kw_m: dict[str, Any]
    ps: BarrierScene
    ms: BarrierScene
    lv: np.ndarray
    flow: FlowCheck | None = None  # the model flow and the flume's limits (the verdict's)
    loaded: BarrierScene | None = None  # the prototype, its sensors pulling force x lambda^3

    def jobs(self, *, keep_states: bool = False) -> list[tuple]:
        """(sweep, args, kwargs) of the model, then of the prototype (run_jobs' form);
        `keep_states`: each keeps its states (`Run.states`: the bands' variants start from
        them, `printgen.verification.bands.warm_start`)."""
        keep = {"keep_states": True} if keep_states else {}
        return [(sweep, (self.ms, self.lv), self.kw_m | keep),
                (sweep, (self.ps, self.lv), self.kw_p | keep)]

    def sensor_jobs(self) -> list[tuple]:
        """The sweep of the prototype with sensors pulling as much of its load as the model's,
        when they pull more than SENSOR_SHARE of the model's (`printgen.verification.sensors`);
        none otherwise."""
        return [] if self.loaded is None else [(sweep, (self.loaded, self.lv), self.kw_p)]

    def verified(self, model: Run, proto: Run, ce: CounterExample | None = None,
                 loaded: Run | None = None) -> Verification:
        """The comparison of the two sweeps, at the levels where both converged (`loaded`:
        the run of `sensor_jobs`)."""
        check = self._sensors(model, loaded)
        (proto, model), load_rec = self.compared(model, proto)
        mm = compare(proto.deformation, model.deformation)
        start = compare(increments(proto.deformation), increments(model.deformation))
        return Verification(self.case.title, proto, model, mm, explain(mm), ce, start,
                            len(self.lv), load_rec, flow=self.flow, sensors=check,
                            loaded_prototype=loaded)

    def compared(self, model: Run, proto: Run) -> tuple[tuple[Run, Run], dict[str, Any]]:
        """The runs (prototype, model) as `verified` compares them, at the levels where both
        converged, with the load case's record (`stated`): the loaded prototype's sweep
        plays no part, so the prototype's run is known as soon as the pair is."""
        bad = set(proto.failed) | set(model.failed)
        if bad:  # compare only where both barriers converged
            keep = np.array([lvl not in bad for lvl in self.lv])
            proto = _only(proto, keep)
            model = _only(model, keep)
        return stated(self.case, (proto, model), (self.kw_p["site"], self.kw_m["site"]))

    def _sensors(self, model: Run, loaded: Run | None) -> SensorCheck:
        force, mm = scene_sensor_force(self.ms), None
        if loaded is not None:
            bad = set(loaded.failed) | set(model.failed)
            keep = np.array([lvl not in bad for lvl in self.lv])
            mm = compare(_only(loaded, keep).deformation, _only(model, keep).deformation)
        return sensor_check(self.ms, force, self.lv, mm)


def verify_plan(p: Prototype, d: Design, *, load: str | LoadCase | None = None,
                lv: np.ndarray | None = None, mounting: str | None = None,
                prototype: BarrierScene | None = None, sensors: bool = True) -> VerifyPlan:
    """The sweeps of `verify` (default levels: the usual ones and the case's own).
    `prototype`: the prototype's scene, already built under the same load case and mounting
    (the design search's one prototype sweep's); `sensors`: False when the caller does not
    sweep `sensor_jobs` (no loaded prototype scene is built)."""
    case, kw_p, kw_m, ps, ms = barriers(p, d, load, mounting, prototype)
    if lv is None:  # the usual levels and the case's own (the jam's discharge steps)
        own = case.levels_for(ms, kw_m["site"])
        lv = levels() if own is None else np.unique(np.concatenate([levels(), own]))
    force, loaded = sensor_force(p), None
    if sensors and needs_loaded_prototype(ms, force):  # forces scale as lambda^-3
        loaded = build_scene(p, SceneOptions(mounting=ps.mounting, load=case,
                                             sensor_force=force * d.scale**3))
    return VerifyPlan(case, kw_p, kw_m, ps, ms, np.asarray(lv, dtype=float),
                      flow=scale_targets(p, d.scale).flow, loaded=loaded)


def verify(p: Prototype, d: Design, *, load: str | LoadCase | None = None,
           lv: np.ndarray | None = None, counterexample: bool = False,
           mounting: str | None = None) -> Verification:
    """Sweep both barriers under the same relative loading of load case `load` (default
    hydrostatic) and compare them; both are mounted by `mounting` (default: the prototype
    file's [flume] lateral)."""
    plan = verify_plan(p, d, load=load, lv=lv, mounting=mounting)
    jobs = plan.jobs() + plan.sensor_jobs()  # longest first
    if counterexample:
        jobs.append((steel_counterexample, (d.scale,), {}))
    model, proto, *rest = run_jobs(jobs)
    loaded = rest.pop(0) if plan.loaded is not None else None
    return plan.verified(model, proto, rest[0] if rest else None, loaded)


def stated(case: LoadCase, runs: tuple[Run, Run], sites: tuple[Site, Site]
           ) -> tuple[tuple[Run, Run], dict[str, Any]]:
    """The runs (prototype, model) with a row stating what `case` used at their levels (the
    velocity, the discharge) added to their scenes' assumptions, and the record of it."""
    rec: dict[str, Any] = {"case": case.name, "spec": case.spec, "title": case.title}
    out = []
    for who, run, site in zip(("prototype", "model"), runs, sites, strict=True):
        values, text = case.describe(run.scene, site, run.deformation.levels)
        rec[who] = {"levels": run.deformation.levels, **values}
        if text:
            row = (f"loading: {case.name} at each level", text,
                   ("printgen (report.json: verification.load, or verification.by_load.<case> "
                    "for make --loads)"))
            run = dataclasses.replace(run, scene=noted(run.scene, row))
        out.append(run)
    return (out[0], out[1]), rec


def _only(run: Run, keep: np.ndarray) -> Run:
    return dataclasses.replace(run, deformation=run.deformation.only(keep))


@dataclass(frozen=True)
class CounterExample:
    """The simple barrier (scene simple-free-top, hydrostatic at h = h_B) at 1:scale: the
    prototype, the model with E scaled by 1/lambda, and the model with steel E."""

    scale: float
    deflection: dict[str, float]  # variant -> mid-height deflection / width
    lowering: dict[str, float]  # variant -> top-centre lowering / height


def steel_counterexample(scale: float) -> CounterExample:
    """Why stiffness must be scaled: steel at every scale deflects less and less as lambda
    grows (Lambert et al. 2023, Fig. 2), while E / lambda reproduces the prototype."""
    from printgen.solver.scenes import SIMPLE, simple_scene

    variants = {"prototype (lambda = 1)": (1.0, SIMPLE["modulus"]),
                f"1:{scale:g}, E scaled by 1/lambda": (scale, SIMPLE["modulus"] / scale),
                f"1:{scale:g}, steel E": (scale, SIMPLE["modulus"])}
    defl, low = {}, {}
    for name, (lam, modulus) in variants.items():
        sc = simple_scene(scale=lam, modulus=modulus, pinned_top=False, drag=False)
        r = solver.solve(sc.net, sc.loads_at(1.0), tol=SOLVER_TOL)
        if not r.converged:
            raise SolverError(f"simple barrier {name}: {r.reason}")
        defl[name] = float(r.displacements[sc.centre, 1] / sc.width)
        low[name] = float(-r.displacements[sc.top_centre, 2] / sc.height)
    return CounterExample(scale, defl, low)
