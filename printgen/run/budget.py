"""The size of a `make` run, before any of it is done: nodes, unknowns, memory and time.

The verification solves two nets over 23 load levels (prototype and model, in parallel on two
cores), then the model's uncertainty-band variants; the meshes step builds one solid strand per
model net segment. Both costs grow with the node count, which follows from the meshes alone (no
net is built here). The constants are measured on the 1:40 example with the solver's fast path
(`examples/realistic_barrier.toml`, one core per sweep: 518 prototype nodes in 0.43 s, 365
model nodes in 0.40 s, 1998 nodes in 2.5 s, 7776 nodes in 21 s; bands 2.7 s; meshes 2.9 s;
whole `make` 9.0 s) and on the simple barrier (free top, sensor wires as segments: model 2481
nodes in ~16 s beside the prototype's sweep, bands 26 s, whole `make` 45 s); the estimate is meant to be right within a factor of about two, enough
to stop a run that would take an hour.
"""

from __future__ import annotations

import contextlib
import math
import os
from collections.abc import Callable, Iterator
from dataclasses import dataclass

from printgen.barrier.patterns import get_pattern
from printgen.design.record import Design
from printgen.errors import InputError
from printgen.inputs.prototype import Prototype
from printgen.workers import cores, reporting

# About a minute of `make` on 2 cores (issue 16); the bundled simple barrier
# (examples/simple_barrier.toml, free top) is estimated at ~45 s and takes ~45 s.
DEFAULT_LIMIT_S = 60.0
SWEEP_S_AT_REFERENCE = 0.45  # one net over the 23 load levels of the sweep, one core
REFERENCE_NODES = 500  # node count at which SWEEP_S_AT_REFERENCE was measured
SWEEP_EXPONENT = 1.45  # sweep time grows as nodes^1.45 (518 -> 1998 -> 7776 nodes)
# Uncertainty bands (verification/bands.py): refinement test and model variants on coarsened nets
# after the nominal sweeps: 2.7 s on the 1:40 example, ~1.4 x the model's sweep on the simple.
BANDS_FACTOR = 1.5
BANDS_MIN_S = 2.5
# A net without border cables (free top, anchored on bed and banks) is slack at low water:
# the simple barrier's 1:40 model takes ~1450 Newton iterations against 197 for the realistic
# (its sweep: 16 s in make against 4.6 s for a net of its size with border cables).
FREE_TOP_MODEL_FACTOR = 3.5
VERIFY_FIXED_S = 1.5  # worker start, the steel counter-example, the comparison
MESH_S_PER_SEGMENT = 1e-4  # meshes step per model net segment (simple 1:40: 4962 in 0.46 s)
# The parts' steps got faster (toolpaths built once, verification in a helper process beside
# them): make of the 1:40 example measures ~3.9 s (bench make) to ~5 s (README's demo), which
# the sum of the constants below puts at ~7 s (was 9.5 s: 2.4x the measured run).
CABLE_PARTS_S = 1.0  # the four cables, their eyelets and plate
CABLE_PART_S = CABLE_PARTS_S / 4  # one cable: mesh, 3MF, slicer profile, G-code, its place
FIXED_S = 1.5  # planning, slicer profiles, G-code, previews, report
# verify --measured: the fit's bounded Brent search runs this many sweeps of the model on the
# band's net (coarsened COARSENED_BY each way, so about COARSENED_BY^2 fewer nodes)
FIT_SWEEPS = 20
COARSENED_BY = 2
BASE_MEMORY_B = 150e6  # Python, numpy, scipy and the geometry libraries
MEMORY_B_PER_NODE = 20e3  # sparse factor, path results kept per level (1998 nodes: +39 MB)
COARSEN_MAX = 1000.0  # search bound for the mesh factor that fits


@dataclass(frozen=True)
class NetSize:
    """One solver net: nodes, free unknowns (3 per node) and its share of the cost."""

    name: str
    nodes: int
    unknowns: int
    seconds: float
    memory_b: float


@dataclass(frozen=True)
class Estimate:
    """The whole run: the nets, the meshes step, wall-clock time on `cores`, peak memory."""

    nets: tuple[NetSize, ...]
    mesh_segments: int
    seconds: float
    memory_b: float
    cores: int

    def summary(self) -> str:
        nets = ", ".join(f"{n.name} {n.nodes:,} nodes / {n.unknowns:,} unknowns"
                         for n in self.nets) or "no solver sweep"
        return (f"{nets}; {self.mesh_segments:,} model strand segments; about "
                f"{self.seconds:.0f} s and {self.memory_b / 1e9:.1f} GB on {self.cores} cores")

    def to_record(self) -> dict:
        return {"nets": {n.name: {"nodes": n.nodes, "unknowns": n.unknowns} for n in self.nets},
                "mesh_segments": self.mesh_segments, "memory_bytes": round(self.memory_b),
                "cores": self.cores}


def prototype_nodes(p: Prototype, factor: float = 1.0) -> int:
    """Nodes of the prototype scene with its meshes `factor` times coarser."""
    ax, ay = p.net.mesh_x * factor, p.net.mesh_y * factor
    return get_pattern(p.net.pattern).nodes(p.width, p.height, ax, ay)


def model_nodes(d: Design, factor: float = 1.0) -> int:
    n = d.net
    return get_pattern(n.pattern).nodes(n.width_mm, n.height_mm, n.mesh_x_mm * factor,
                                        n.mesh_y_mm * factor)


def sweep_cores() -> int:
    """Cores the verification's two sweeps (prototype, model) run on: 1 under
    PRINTGEN_SERIAL, else up to 2."""
    return 1 if os.environ.get("PRINTGEN_SERIAL") else min(2, cores())


def sweep_seconds(nodes: int) -> float:
    """One net over the load path on one core."""
    return SWEEP_S_AT_REFERENCE * (nodes / REFERENCE_NODES) ** SWEEP_EXPONENT


@dataclass(frozen=True)
class Work:
    """What a command runs: `sweep` the verification, `parts` the printable files (make),
    `fit` a measured test's fit (verify --measured)."""

    sweep: bool = True
    parts: bool = True
    fit: bool = False
    model_follows: bool = True  # the model's mesh is the prototype's scaled (not a design's)


MAKE = Work()


def estimate(p: Prototype, d: Design, *, cores: int, sweep: bool = True,
             proto_factor: float = 1.0, model_factor: float = 1.0,
             work: Work | None = None) -> Estimate:
    """The run's size (`sweep`: the verification runs; `work`: what else, default make's);
    the factors coarsen the prototype's or the model's meshes."""
    work = work or Work(sweep=sweep)
    m_nodes = model_nodes(d, model_factor)
    slow = 1.0 if d.cables else FREE_TOP_MODEL_FACTOR
    nets: tuple[NetSize, ...] = ()
    if work.sweep:
        nets = tuple(NetSize(name, n, 3 * n, factor * sweep_seconds(n), MEMORY_B_PER_NODE * n)
                     for name, n, factor in (("prototype", prototype_nodes(p, proto_factor), 1.0),
                                             ("model", m_nodes, slow)))
    verify = 0.0
    if nets:
        times = [n.seconds for n in nets]
        nominal = sum(times) if cores < 2 else max(times)
        bands = max(BANDS_MIN_S, BANDS_FACTOR * nets[1].seconds)
        verify = VERIFY_FIXED_S + nominal + bands
        if work.fit:
            verify += FIT_SWEEPS * slow * sweep_seconds(m_nodes / COARSENED_BY**2)
    segments = 2 * m_nodes if work.parts else 0
    parts = (FIXED_S + MESH_S_PER_SEGMENT * segments + CABLE_PART_S * len(d.cables)
             if work.parts else 0.0)
    memory = BASE_MEMORY_B + sum(n.memory_b for n in nets)
    return Estimate(nets, segments, parts + verify, memory, cores)


def check_budget(p: Prototype, d: Design, *, limit_s: float, cores: int,
                 sweep: bool = True, work: Work | None = None) -> Estimate:
    """Return the estimate; raise InputError with the estimate, the limit, the option that
    raises it and the least coarsening of the meshes that fits, when it is over the limit.
    `work`: what the command runs (default make's, with the verification when `sweep`)."""
    if not (math.isfinite(limit_s) and limit_s > 0):
        raise InputError(f"--time-limit {limit_s:g} s must be a positive number of seconds")
    work = work or Work(sweep=sweep)
    est = estimate(p, d, cores=cores, work=work)
    if est.seconds <= limit_s:
        return est
    fix = coarsest_fix(p, d, limit_s=limit_s, cores=cores, work=work)
    which = ("the default, about a minute of make on 2 cores" if limit_s == DEFAULT_LIMIT_S
             else "from --time-limit")
    raise InputError(f"this run is too big: {est.summary()}; the limit is {limit_s:g} s "
                     f"({which}). Raise it with --time-limit "
                     f"{math.ceil(est.seconds * 1.5 / 60) * 60:g}, or {fix}")


def coarsest_fix(p: Prototype, d: Design, *, limit_s: float, cores: int,
                 work: Work = MAKE) -> str:
    """The smallest uniform coarsening of the meshes that fits `limit_s`, as advice."""
    user_model = p.model.mesh_x_mm is not None or not work.model_follows
    model_scales = not user_model  # the model mesh follows the prototype's unless [model] sets it

    def fits(f: float) -> bool:
        return estimate(p, d, cores=cores, work=work, proto_factor=f,
                        model_factor=f if model_scales else 1.0).seconds <= limit_s

    lo, hi = 1.0, COARSEN_MAX
    if not fits(hi):
        if user_model and estimate(p, d, cores=cores, work=work, proto_factor=hi,
                                   model_factor=hi).seconds <= limit_s:
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
    at each load level (from `printgen.workers.report_progress`). None: no reporting."""
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
