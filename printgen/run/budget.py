"""The size of a `make` run, before any of it is done: nodes, unknowns, solver work, memory and
time.

The verification's solver work is predicted sweep by sweep (`sweeps`), from the run's structure
and the meshes alone (no net is built here): the prototype's and the model's nets over the load
levels (23: h / h_B = 0 to 1.1 by 0.05, `printgen.verification.preprint.levels`), each more load
case of `make --loads` the same, the band's refinement test (the model on a net COARSENINGS[0]
times coarser), then each band variant of the model (`printgen.verification.variants
.model_variants`: 5 on the simple barrier, 9 on the 1:40 example) on the design's own net: the
refinement test may pick a coarser one, which the estimate does not foresee (on both examples
it keeps the design's net), so a run whose variants coarsen is estimated high. A sweep's work
is its levels times the Newton iterations per level (ITERATIONS_PER_LEVEL, for a net with
border cables or one with a free top, growing slowly with the unknowns), its CPU time on one
core that many iterations of ITERATION_S + ITERATION_S_PER_UNKNOWN x its unknowns (3 per
node). The run counts the same work (`counted_work`, report.json "verification" ->
"solver_work" against "size" -> "solver_work"); tests/test_budget.py checks the prediction
against the count on both examples and `printgen bench make` (benchmarks/bench_make.py)
measures the constants, the estimate against the measured time and the CPU. `verify
--measured` adds its fit's sweeps as the fit plans them (`FitPlan`: every sweep it may run, on
its nets, over its levels; `printgen bench fit` measures them). The parts' steps (meshes,
slicer profiles, G-code, previews) have constants of their own. The estimate is meant
to be right within a factor of about two, enough to stop a run that would take an hour.
"""

from __future__ import annotations

import contextlib
import math
import os
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import Any

from printgen.barrier.patterns import get_pattern
from printgen.errors import InputError
from printgen.executor.local import reporting
from printgen.executor.start import cores
from printgen.inputs.prototype import Prototype
from printgen.scaling.record import Design
from printgen.units import RHO_WATER, G

# About a minute of `make` on 2 cores: the bundled simple barrier (free top) and the 1:40
# example both fit (benchmarks/measurements.md#make-no-default-stop).
DEFAULT_LIMIT_S = 60.0
DESIGN_LIMIT_S = 600.0  # a design search runs minutes by nature; the limit stops a runaway
# The search verifies its best candidates, soft nets close to the prototype's deformation: each
# takes several times the Newton iterations of select's pick (measurements.md#design-verification)
SEARCH_VERIFY_FACTOR = 6.0
# The advice's candidates (printgen.verification.advice) are nets near the design's, not the
# search's softest: 1.1 to 1.9 x its Newton iterations on the 1:40 example (134 against 153-254)
ADVICE_SWEEP_FACTOR = 1.5
LONG_RUN_S = 30.0  # runs estimated longer show their estimate and progress (make, on a terminal)
LEVELS = 23  # load levels of a sweep (verify.levels(): 0 to 1.1 by 0.05; tests/test_budget.py)
# Newton iterations (chord steps included) per load level, averaged over a run's sweeps (the
# nominal pair, the refinement test and the band's variants; a variant's slack strands may
# take 4 x the nominal's), at REFERENCE_UNKNOWNS, growing as unknowns^ITERATION_GROWTH: a net
# with border cables and one with a free top differ. Counted by bench make at 1:40 on both
# examples and refitted when the solver changes (benchmarks/measurements.md#budget-iterations).
ITERATIONS_PER_LEVEL = {"border cables": 8.4, "free top": 6.9}
REFERENCE_UNKNOWNS = 1000
ITERATION_GROWTH = 0.34
# CPU of one iteration on one core: ITERATION_S + ITERATION_S_PER_UNKNOWN x unknowns, a least-
# squares fit (bench make) over the sweeps of both examples at 1:40 (1000 to 3500 unknowns),
# given their counted iterations, in the reference machine's seconds (printgen.run.speed;
# benchmarks/measurements.md#budget-iteration-cpu).
ITERATION_S = 1.2e-3
ITERATION_S_PER_UNKNOWN = 2.9e-6
# CPU beside the sweeps: the steel counter-example (a job beside the nominal pair) and the
# verification's report (the comparison, its figures and tables); VERIFY_REPORT_S also stands
# for what the estimate does not count (the fork server's and the helper's start, the hand-over
# of the sweeps). Measured by bench make and bench timeline
# (benchmarks/measurements.md#budget-verification-extras).
COUNTEREXAMPLE_S = 2.0
VERIFY_REPORT_S = 6.0
MESH_S_PER_SEGMENT = 1e-4  # meshes step per model net segment
# The parts' steps, CPU of make's own process (bench make, 1:40; the kit's previews are drawn
# in the helper's workers: benchmarks/measurements.md#budget-parts)
CABLE_PARTS_S = 1.3  # the four cables: meshes, 3MF, plate, slicer profiles, G-code
CABLE_PART_S = CABLE_PARTS_S / 4  # one cable
FIXED_S = 2.0  # start-up, planning, the net's parts and slicer profile, the report
BASE_MEMORY_B = 150e6  # Python, numpy, scipy and the geometry libraries
MEMORY_B_PER_NODE = 20e3  # sparse factor, path results kept per level (1998 nodes: +39 MB)
COARSEN_MAX = 1000.0  # search bound for the mesh factor that fits
# A scale series steps its load by 0.25, five times a sweep's step: 1.55 x a sweep's Newton
# iterations per level on the paper's series of the simple barrier (652 counted over its 10
# cases that are not the prototype scaled, 4 loaded levels each, against 10.5 a level);
# then its start-up and report (wall of the command less its cases': 3.3 s)
# (benchmarks/measurements.md#series-estimate)
SERIES_STEP_FACTOR = 1.55
SERIES_REPORT_S = 3.0


@dataclass(frozen=True)
class NetSize:
    """One solver net: nodes, free unknowns (3 per node) and its share of the cost."""

    name: str
    nodes: int
    unknowns: int
    seconds: float
    memory_b: float


@dataclass(frozen=True)
class SweepWork:
    """One predicted sweep: its net's unknowns, load levels and Newton iterations; `group`:
    "nominal" (the prototype and model pair of a load case), "band" (the variants) and
    "pooled" (the refinement test's sweep), all on one pool on the sweep cores; "serial":
    alone, after them (a one-factor fit's search); "fit": after them, shared on the sweep
    cores (the multi-parameter fit's batches)."""

    name: str
    unknowns: int
    levels: int
    iterations: float
    group: str = "serial"

    @property
    def seconds(self) -> float:
        """CPU on one core."""
        return self.iterations * (ITERATION_S + ITERATION_S_PER_UNKNOWN * self.unknowns)


@dataclass(frozen=True)
class Estimate:
    """The whole run: the nets, the meshes step, wall-clock time on `cores`, peak memory;
    `sweeps`: the verification's predicted solver work; `verification_s`, `parts_s`: the
    wall times of the verification and of the parts' steps alone."""

    nets: tuple[NetSize, ...]
    mesh_segments: int
    seconds: float
    memory_b: float
    cores: int
    sweeps: tuple[SweepWork, ...] = ()
    verification_s: float = 0.0
    parts_s: float = 0.0
    speed: float = 1.0  # this machine's time over the reference machine's (printgen.run.speed)
    advice_s: float = 0.0  # the advice's wall time, when the verdict is not PASS (`advice_seconds`)

    def summary(self) -> str:
        nets = ", ".join(f"{n.name} {n.nodes:,} nodes / {n.unknowns:,} unknowns"
                         for n in self.nets) or "no solver sweep"
        return (f"{nets}; {self.mesh_segments:,} model strand segments; about "
                f"{self.seconds:.0f} s and {self.memory_b / 1e9:.1f} GB on {self.cores} cores "
                f"(this machine takes {self.speed:.2g} x the reference machine's time)")

    def to_record(self) -> dict:
        return {"nets": {n.name: {"nodes": n.nodes, "unknowns": n.unknowns} for n in self.nets},
                "mesh_segments": self.mesh_segments, "memory_bytes": round(self.memory_b),
                "cores": self.cores, "solver_work": work_totals(
                    (s.unknowns, s.iterations) for s in self.sweeps)}


def work_totals(sweeps: Iterable[tuple[int, float]]) -> dict[str, int]:
    """The sweeps' count, Newton iterations and iterations x unknowns, from (unknowns,
    iterations) pairs."""
    rows = list(sweeps)
    return {"sweeps": len(rows), "iterations": round(sum(it for _, it in rows)),
            "iteration_unknowns": round(sum(n * it for n, it in rows))}


def counted_work(runs: Iterable[dict[str, Any]]) -> dict[str, Any]:
    """What the solver did in a run, from each sweep's `Run.work()`: the totals of
    `work_totals` and the rows (their CPU seconds under the volatile key "time_s")."""
    rows = list(runs)
    return {**work_totals((r["unknowns"], r["iterations"]) for r in rows), "runs": rows}


def prototype_nodes(p: Prototype, factor: float = 1.0) -> int:
    """Nodes of the prototype scene with its meshes `factor` times coarser."""
    ax, ay = p.net.mesh_x * factor, p.net.mesh_y * factor
    return get_pattern(p.net.pattern).nodes(p.width, p.height, ax, ay)


def model_nodes(d: Design, factor: float = 1.0) -> int:
    n = d.net
    return get_pattern(n.pattern).nodes(n.width_mm, n.height_mm, n.mesh_x_mm * factor,
                                        n.mesh_y_mm * factor)


def run_cores(serial: bool, workers: int | None) -> int:
    """Cores the parallel work of `design` or `series` runs on, for their estimates: 1
    serially, else its `workers` (default: up to 2, this machine's pool)."""
    return 1 if serial else (workers or min(2, cores()))


def sweep_cores() -> int:
    """Cores the verification's two sweeps (prototype, model) run on: 1 under
    PRINTGEN_SERIAL, else up to 2."""
    return 1 if os.environ.get("PRINTGEN_SERIAL") else min(2, cores())


@dataclass(frozen=True)
class FitPlan:
    """The sweeps of a measured test's fit (verify --measured), as the fit plans them
    (`printgen.verification.fit.planned_sweeps`, `measured.FACTOR_EVALUATIONS`): `runs`,
    (mesh coarsening of the design's net, sweeps) pairs; `levels`, the load levels of each
    sweep (h / h_B = 0 and the measured ones); `parallel`: run in batches on the sweep cores
    (the multi-parameter fit) or one after the other (the one-factor search)."""

    runs: tuple[tuple[int, int], ...]
    levels: int
    parallel: bool = False

    @property
    def sweeps(self) -> int:
        return sum(n for _, n in self.runs)


@dataclass(frozen=True)
class Work:
    """What a command runs: `sweep` the verification, `parts` the printable files (make),
    `fit` a measured test's fit (verify --measured); `cases`: the load cases swept (make
    --loads adds its other cases' nominal pairs)."""

    sweep: bool = True
    parts: bool = True
    fit: bool = False
    model_follows: bool = True  # the model's mesh is the prototype's scaled (not a design's)
    cases: int = 1
    fit_plan: FitPlan | None = None  # the fit's sweeps (with `fit`; None: `default_fit`)


def default_fit() -> FitPlan:
    """A one-factor fit of a measurement not yet read: its search's sweeps on the design's
    net over every sweep level (the most a test can measure)."""
    from printgen.verification.measured import FACTOR_EVALUATIONS

    return FitPlan(((1, FACTOR_EVALUATIONS + 2),), LEVELS)


MAKE = Work()


def band_variants(p: Prototype, d: Design) -> int:
    """The model variants the uncertainty band sweeps (as `verify` mounts the model)."""
    from printgen.scene.scenes import lateral_mounting
    from printgen.verification.preprint import free_section
    from printgen.verification.variants import model_variants

    return len(model_variants(d, lateral_mounting(p), free_section(p))[0])


def sweeps(p: Prototype, d: Design, *, proto_factor: float = 1.0, model_factor: float = 1.0,
           work: Work = MAKE, variants: int | None = None) -> tuple[SweepWork, ...]:
    """The verification's sweeps and each one's predicted work (module docstring);
    `variants`: the band's count when known (default: `band_variants`)."""
    from printgen.verification.bands import COARSENINGS

    kind = "border cables" if d.cables else "free top"

    def one(name: str, nodes: float, group: str) -> SweepWork:
        return SweepWork(name, round(3 * nodes), LEVELS,
                         LEVELS * iterations_per_level(kind, 3 * nodes), group)

    m_nodes = model_nodes(d, model_factor)
    out = []
    for _ in range(work.cases):
        out += [one("prototype", prototype_nodes(p, proto_factor), "nominal"),
                one("model", m_nodes, "nominal")]
    out.append(one(f"refinement x{COARSENINGS[0]}", m_nodes / COARSENINGS[0] ** 2, "pooled"))
    if sensors_compared(p, d):  # the prototype again, its wires pulling force x lambda^3
        out.append(one("prototype, sensors scaled", prototype_nodes(p, proto_factor), "pooled"))
    n_band = band_variants(p, d) if variants is None else variants
    out += [one("band variant", m_nodes, "band")] * n_band
    if n_band:  # the prototype's own band
        from printgen.verification.variants import prototype_variants

        out += [one("prototype band variant", prototype_nodes(p, proto_factor), "pooled")
                ] * len(prototype_variants(p))
    if work.fit:
        plan = work.fit_plan or default_fit()
        group = "fit" if plan.parallel else "serial"
        for k, n in plan.runs:
            nodes = model_nodes(d, model_factor * k)
            out += [SweepWork(f"fit x{k}" if k > 1 else "fit", round(3 * nodes), plan.levels,
                              plan.levels * iterations_per_level(kind, 3 * nodes), group)] * n
    return tuple(out)


def sensors_compared(p: Prototype, d: Design) -> bool:
    """True when the sensors pull more than their threshold share of the model's water load
    (`printgen.verification.sensors`; here from the continuous hydrostatic resultant, no net
    built), so the verification sweeps the prototype a second time."""
    from printgen.scene.readings import SENSORS
    from printgen.verification.preprint import sensor_force
    from printgen.verification.sensors import SENSOR_LEVEL, SENSOR_SHARE

    w, h = p.width / d.scale, SENSOR_LEVEL * p.height / d.scale
    return len(SENSORS) * sensor_force(p) > SENSOR_SHARE * RHO_WATER * G * w * h**2 / 2


def iterations_per_level(kind: str, unknowns: float) -> float:
    """Predicted Newton iterations per load level of a net of `kind` (ITERATIONS_PER_LEVEL)."""
    return ITERATIONS_PER_LEVEL[kind] * (unknowns / REFERENCE_UNKNOWNS) ** ITERATION_GROWTH


def verification_seconds(work: tuple[SweepWork, ...], cores: int) -> tuple[float, float]:
    """(wall, CPU) seconds of the verification on `cores`: every sweep and the counter-example
    on one pool (printgen.verification.pooled), shared out, but no shorter than the model's
    nominal sweep then one band variant (a variant starts once the model's sweep is done);
    then the report (VERIFY_REPORT_S)."""
    c = max(1, min(cores, 2))
    nominal = [s.seconds for s in work if s.group == "nominal"]
    band = [s.seconds for s in work if s.group == "band"]
    jobs = [s.seconds for s in work if s.group not in ("serial", "fit")] + (
        [COUNTEREXAMPLE_S] if nominal else [])
    serial = sum(s.seconds for s in work if s.group == "serial")
    fit = [s.seconds for s in work if s.group == "fit"]  # after the band, in batches
    chain = (nominal[1] if len(nominal) > 1 else 0.0) + max(band, default=0.0)
    wall = max(_shared(jobs, c), chain) + serial + _shared(fit, c)
    return VERIFY_REPORT_S + wall, VERIFY_REPORT_S + sum(jobs) + serial + sum(fit)


def _shared(jobs: list[float], cores: int) -> float:
    """Wall time of independent jobs on `cores` workers: the longest, or their sum shared."""
    return max(max(jobs), sum(jobs) / cores) if jobs else 0.0


def estimate(p: Prototype, d: Design, *, cores: int, sweep: bool = True,
             proto_factor: float = 1.0, model_factor: float = 1.0,
             work: Work | None = None, variants: int | None = None,
             speed: float = 1.0) -> Estimate:
    """The run's size (`sweep`: the verification runs; `work`: what else, default make's);
    the factors coarsen the prototype's or the model's meshes; `variants`: as `sweeps`. On 2
    cores make runs its verification in a helper process beside the parts' steps: its wall
    time is then the longer of the two, or their CPU shared out on the cores when more.
    `speed`: this machine's time over the reference machine's (`speed.speed_factor`); every
    time of the estimate is the reference machine's times it (the solver work is not)."""
    work = work or Work(sweep=sweep)
    m_nodes = model_nodes(d, model_factor)
    nets: tuple[NetSize, ...] = ()
    run: tuple[SweepWork, ...] = ()
    verify = verify_cpu = 0.0
    if work.sweep:
        run = sweeps(p, d, proto_factor=proto_factor, model_factor=model_factor, work=work,
                     variants=variants)
        nets = tuple(NetSize(s.name, s.unknowns // 3, s.unknowns, s.seconds,
                             MEMORY_B_PER_NODE * s.unknowns / 3) for s in run[:2])
        verify, verify_cpu = verification_seconds(run, cores)
    segments = 2 * m_nodes if work.parts else 0
    parts = (FIXED_S + MESH_S_PER_SEGMENT * segments + CABLE_PART_S * len(d.cables)
             if work.parts else 0.0)
    seconds = parts + verify
    if work.parts and work.sweep and cores > 1:  # the verification in make's helper
        seconds = max(verify, parts, (verify_cpu + parts) / min(cores, 2))
    memory = BASE_MEMORY_B + sum(n.memory_b for n in nets)
    advice = advice_seconds(d, cores) if work.sweep else 0.0
    return Estimate(nets, segments, speed * (seconds + advice), memory, cores, run,
                    speed * verify, speed * parts, speed, speed * advice)


def advice_seconds(d: Design, cores: int) -> float:
    """Wall seconds of the advice of a run whose verdict is not PASS
    (printgen.verification.advice), counted in every estimate since the verdict is not known
    before: its screen (ADVICE_SCREEN nets at SCREEN_RATE per second), then at most
    ADVICE_ROUNDS x ADVICE_NETS sweeps of nets on the band's net (the design's own on both
    examples), shared on the cores, and two sweeps of the design's own net (the weaker
    sensors', a confirmation). A candidate's sweep takes ADVICE_SWEEP_FACTOR times the
    design's iterations."""
    from printgen.search.space import SCREEN_RATE
    from printgen.verification.advice import ADVICE_NETS, ADVICE_ROUNDS, ADVICE_SCREEN

    kind = "border cables" if d.cables else "free top"
    nodes = model_nodes(d)

    def one(n: float) -> float:
        return SweepWork("advice", round(3 * n), LEVELS,
                         LEVELS * iterations_per_level(kind, 3 * n)).seconds

    nets = ADVICE_ROUNDS * ADVICE_NETS * one(nodes) * ADVICE_SWEEP_FACTOR
    return ADVICE_SCREEN / SCREEN_RATE + nets / max(1, min(cores, 2)) + 2 * one(nodes)


def check_budget(p: Prototype, d: Design, *, limit_s: float, cores: int,
                 sweep: bool = True, work: Work | None = None,
                 speed: float | None = None) -> Estimate:
    """Return the estimate; raise InputError with the estimate, the limit, the option that
    raises it and the least coarsening of the meshes that fits, when it is over the limit.
    `work`: what the command runs (default make's, with the verification when `sweep`);
    `speed`: as `estimate` (None: this machine's, measured once per process)."""
    if not (math.isfinite(limit_s) and limit_s > 0):
        raise InputError(f"--time-limit {limit_s:g} s must be a positive number of seconds")
    work = work or Work(sweep=sweep)
    if speed is None:
        from printgen.run.speed import speed_factor

        speed = speed_factor()
    variants = band_variants(p, d) if work.sweep else 0  # read once: the profiles' files
    est = estimate(p, d, cores=cores, work=work, variants=variants, speed=speed)
    if est.seconds <= limit_s:
        return est
    fix = coarsest_fix(p, d, limit_s=limit_s, cores=cores, work=work, variants=variants,
                       speed=speed)
    which = ("the default, about a minute of make on 2 cores" if limit_s == DEFAULT_LIMIT_S
             else "from --time-limit")
    fit = _fit_share(est) if work.fit else ""
    if fit and work.fit_plan is not None and work.fit_plan.parallel:
        fix += (f"; or fit one factor of the net (--fit stiffness), a search of at most "
                f"{default_fit().sweeps} sweeps")
    raise InputError(f"this run is too big: {est.summary()}{fit}; the limit is {limit_s:g} s "
                     f"({which}). Raise it with --time-limit "
                     f"{math.ceil(est.seconds * 1.5 / 60) * 60:g}, or {fix}")


def fit_estimate(est: Estimate) -> float:
    """Seconds of the measured test's fit in `est` (on this machine): its sweeps' CPU, shared
    out on the sweep cores when the fit runs in batches."""
    fit = [s for s in est.sweeps if s.name.startswith("fit")]
    if not fit:
        return 0.0
    c = max(1, min(est.cores, 2)) if fit[0].group == "fit" else 1
    return est.speed * sum(s.seconds for s in fit) / c


def _fit_share(est: Estimate) -> str:
    """The fit's part of an estimate, as words: its sweeps and their time."""
    n = sum(1 for s in est.sweeps if s.name.startswith("fit"))
    return (f", of which the measured test's fit: {n} sweeps, about "
            f"{fit_estimate(est):.0f} s") if n else ""


def prototype_sweep_s(p: Prototype) -> float:
    """CPU seconds (reference machine) of one sweep of the prototype's net over LEVELS
    levels: the cost of a series case, and of a design search's verification sweep (the
    model's net has about as many nodes at any scale)."""
    nodes = prototype_nodes(p)
    kind = "border cables" if p.border is not None else "free top"
    return SweepWork("sweep", 3 * nodes, LEVELS,
                     LEVELS * iterations_per_level(kind, 3 * nodes)).seconds


def check_design_budget(p: Prototype, screened: int, verified: int, *, limit_s: float,
                        cores: int, speed: float | None = None, prototypes: int = 1,
                        levels: int = LEVELS) -> float:
    """Seconds a design search takes on `cores`: `screened` nets at SCREEN_RATE per second,
    `verified` solver verifications (a model sweep each, against the prototype's sweep made
    once per scale: `prototypes`), each sweep over `levels` load levels (--level-step);
    InputError naming both, the limit and the fixes when it passes `limit_s`, before any
    work."""
    from printgen.search.space import SCREEN_RATE

    speed = _checked(limit_s, speed)
    c = max(1, cores)
    one = prototype_sweep_s(p) * levels / LEVELS
    seconds = speed * (screened / SCREEN_RATE + verified * one * SEARCH_VERIFY_FACTOR
                       + prototypes * one) / c
    if seconds > limit_s:
        _too_big(f"design search is too big: {screened:,} nets to screen and {verified} to "
                 f"verify with the solver, about {seconds:.0f} s on {c} cores", seconds,
                 limit_s, "narrow --mesh-x-mm / --mesh-y-mm, --materials or --verify-nets")
    return seconds


def _checked(limit_s: float, speed: float | None) -> float:
    """This machine's speed factor (`speed` when given), once the limit is a valid one."""
    if not (math.isfinite(limit_s) and limit_s > 0):
        raise InputError(f"--time-limit {limit_s:g} s must be a positive number of seconds")
    if speed is None:
        from printgen.run.speed import speed_factor

        speed = speed_factor()
    return speed


def _too_big(what: str, seconds: float, limit_s: float, fixes: str) -> None:
    """InputError: this run's estimate `what`, the limit, the limit that would fit, `fixes`."""
    raise InputError(f"this {what}; the limit is {limit_s:g} s. Raise it with --time-limit "
                     f"{math.ceil(seconds * 1.5 / 60) * 60:g}, or {fixes}")


def check_series_budget(p: Prototype, cases: int, *, limit_s: float, cores: int,
                        speed: float | None = None, levels: int = LEVELS,
                        similar: int = 0) -> tuple[float, float]:
    """(seconds, bytes) a scale series of `cases` solves of the prototype's net takes on
    `cores`: the cases shared out on the cores, each one sweep of `levels` levels (the model
    nets have the prototype's nodes at every scale) of SERIES_STEP_FACTOR times a sweep's
    Newton iterations per level, but for the `similar` cases (the prototype scaled exactly:
    they start from its answer and are not counted), then SERIES_REPORT_S; InputError naming
    both, the limit and the fixes when it passes `limit_s`, before any solve (a net too large
    is refused, not run out of memory)."""
    speed = _checked(limit_s, speed)
    nodes = prototype_nodes(p)
    c = max(1, cores)
    one = prototype_sweep_s(p) * levels / LEVELS * SERIES_STEP_FACTOR
    seconds = speed * (one * math.ceil(max(0, cases - similar) / c) + SERIES_REPORT_S)
    memory = c * (BASE_MEMORY_B + MEMORY_B_PER_NODE * nodes)
    if seconds > limit_s:
        _too_big(f"series is too big: {cases} cases of a {nodes:,}-node net, about "
                 f"{seconds:.0f} s and {memory / 1e9:.1f} GB on {c} cores", seconds, limit_s,
                 "give fewer --scales or --materials, or coarsen the prototype's [net] mesh")
    return seconds, memory


def coarsest_fix(p: Prototype, d: Design, *, limit_s: float, cores: int,
                 work: Work = MAKE, variants: int | None = None, speed: float = 1.0) -> str:
    """The smallest uniform coarsening of the meshes that fits `limit_s`, as advice
    (`variants`: the band's, as `sweeps`; `speed`: as `estimate`)."""
    if variants is None and work.sweep:
        variants = band_variants(p, d)
    user_model = p.model.mesh_x_mm is not None or not work.model_follows
    model_scales = not user_model  # the model mesh follows the prototype's unless [model] sets it

    def fits(f: float) -> bool:
        return estimate(p, d, cores=cores, work=work, proto_factor=f, variants=variants,
                        model_factor=f if model_scales else 1.0, speed=speed).seconds <= limit_s

    lo, hi = 1.0, COARSEN_MAX
    if not fits(hi):
        if user_model and estimate(p, d, cores=cores, work=work, proto_factor=hi,
                                   model_factor=hi, variants=variants,
                                   speed=speed).seconds <= limit_s:
            return ("coarsen [model] mesh_x_mm / mesh_y_mm (or the design's mesh) as well as "
                    "the prototype's net")
        return "no mesh coarsening alone fits; raise --time-limit"
    for _ in range(40):  # bisection to 1e-12 of the range
        mid = math.sqrt(lo * hi)
        lo, hi = (lo, mid) if fits(mid) else (mid, hi)
    return (f"coarsen the prototype's net to mesh_x_m = {p.net.mesh_x * hi:.3g}, mesh_y_m = "
            f"{p.net.mesh_y * hi:.3g} or more (x{hi:.2f}), which fits")


BAR_CELLS = 20  # characters of a text progress bar


@contextlib.contextmanager
def level_bars(progress: Callable[[str], None] | None) -> Iterator[None]:
    """While the block runs, pass `progress` one line of text bars, one per net being solved,
    at each load level (from `printgen.executor.local.report_progress`). None: no reporting."""
    if progress is None:
        yield
        return
    state: dict[str, tuple[float, float]] = {}

    def listener(task: str, done: float, total: float) -> None:
        state[task.rsplit(": ", 1)[-1]] = (done, total)  # "...: prototype" -> "prototype"
        bars = []
        for name, (d, t) in sorted(state.items()):
            full = round(BAR_CELLS * min(max(d / t, 0.0), 1.0)) if t > 0 else 0
            bars.append(f"{name} [{'#' * full}{'.' * (BAR_CELLS - full)}] h/h_B {d:.2f}/{t:g}")
        progress("verification: " + "  ".join(bars))

    with reporting(listener):
        yield
