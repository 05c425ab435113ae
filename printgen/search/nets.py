"""Inverse design (`printgen design`): the printable net that deforms most like the prototype.

Stages over the space of `search_space` (material x strand section x mesh x border):

1. screen every candidate by the analytic membrane law (`screen`): error over 1-40 % strain,
   constraints, similitude break, print time (cheap: thousands per second per core);
2. with the `deformation` objective, verify the best few with the solver (`verifier`, the
   pre-print verification over h / h_B = 0-1.1) and rank them by their deformation mismatch:
   the best net of each of the `verify_nets` best material x section pairs, each with every
   border width, and `select`'s pick for comparison. The candidates whose nets share one graph
   (meshes, pattern) go to one worker job (`SolverBatch`), swept in turn, each load level
   warm-started from the earlier ones' load steps to it (the wave stage's sweeps alike);
3. with the `deformation` objective, nets with printable waved strands, searched by the solver
   on the flume's readings (`printgen.search.waves`): the design takes the best waved net when
   it reads closer to the prototype than the best straight net.

Both stages run on a `printgen.executor.Runner` (this machine's workers, a Dask scheduler, or
serial): each task is a pure function of a small frozen record, so the result does not depend on
where it ran. The solver stage is passed in (`verifier`) because the verification stage sits above
the search stage (`printgen.run.search` wires it); with the `stiffness` objective the search stops
after stage 1.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from printgen.errors import InputError
from printgen.executor import Runner, batches
from printgen.inputs.materials import load_material
from printgen.inputs.prototype import Prototype
from printgen.scaling.plan import make_design
from printgen.scaling.record import Design, NetDesign
from printgen.scaling.selection import select
from printgen.scaling.similitude import scale_targets
from printgen.search.choice import binding_constraints, choice_reasons, rank_key
from printgen.search.pareto import pareto_mask
from printgen.search.per_material import target_sentence
from printgen.search.screen import Screened, screen_batch, strand_section
from printgen.search.space import (
    NetPoint,
    SearchContext,
    SearchSpace,
    default_space,
    grid,
    search_context,
)
from printgen.search.waves import Trial, WaveChoice, WaveTask, wave_stage

OBJECTIVES = ("deformation", "stiffness")
VERIFY_NETS = 3  # nets verified by the solver (each with every border width)
SELECT_KEY = "select"  # key of select's pick among the verified designs


@dataclass(frozen=True)
class VerifyShared:
    """What every solver task shares: the prototype and the load-level step (None: the
    verification's own levels)."""

    prototype: Prototype
    level_step: float | None
    prototype_run: Any = None  # the prototype's sweep, made once per search and shared


@dataclass(frozen=True)
class VerifyTask:
    """One solver task: a design to verify against the prototype."""

    key: str
    design: Design

    @property
    def coarsen(self) -> int:
        """The mesh multiplier of its sweep: 1, the design's own net."""
        return 1


@dataclass(frozen=True)
class VerifyScore:
    """The solver's verdict on one design: RMS mismatch of the normalised deformations
    (over load levels and metrics, relative to the prototype's peak) and per metric."""

    key: str
    mismatch: float
    per_metric: dict[str, float]
    max_rel: float
    ok: bool
    failed_levels: tuple[float, ...]
    iterations: int = 0  # the model sweep's Newton iterations (not in the records: the work)
    cpu_s: float = 0.0  # the model sweep's CPU time in its process (not in the records)


@dataclass(frozen=True)
class SolverBatch:
    """One worker job of a solver stage: tasks (`VerifyTask`, `WaveTask`) whose solver nets
    share one graph (the same meshes, coarsening, pattern and size: their states have one
    shape), swept in turn, each load level of a later sweep also started from the earlier
    sweeps' load steps to that level, shifted onto its own path (the solver keeps the start of
    lowest potential and iterates to its tolerance: a start, never the answer)."""

    tasks: tuple[Any, ...]

    def nodes(self) -> float:
        """The job's size: its solver nets' nodes (mesh cells over the barrier), summed."""
        return sum(t.design.net.width_mm * t.design.net.height_mm
                   / (t.design.net.mesh_x_mm * t.design.net.mesh_y_mm * t.coarsen**2)
                   for t in self.tasks)


def solver_batches(tasks: Sequence[Any]) -> list[SolverBatch]:
    """`tasks` grouped by solver net graph (in task order within a group), the largest job
    first: the worker that takes the last job should not start a long one late. The grouping
    depends on the designs alone, never on the workers: the same results wherever the search
    runs."""
    groups: dict[tuple, list[Any]] = {}
    for t in tasks:
        n = t.design.net
        groups.setdefault((n.pattern, n.mesh_x_mm, n.mesh_y_mm, n.width_mm, n.height_mm,
                           t.coarsen), []).append(t)
    return sorted((SolverBatch(tuple(g)) for g in groups.values()), key=lambda b: -b.nodes())


def in_task_order(tasks: Sequence[Any], jobs: list[SolverBatch], parts: list[list[Any]]
                  ) -> list[Any]:
    """The results of `jobs` (`parts`, job by job) in the order of `tasks` (keys unique)."""
    by_key = {t.key: r for job, part in zip(jobs, parts, strict=True)
              for t, r in zip(job.tasks, part, strict=True)}
    return [by_key[t.key] for t in tasks]


Verifier = Callable[[VerifyShared, SolverBatch], list[VerifyScore]]


@dataclass(frozen=True)
class SearchResult:
    """Everything the design search found at one scale (indices refer to `screened`)."""

    prototype: str
    scale: float
    objective: str
    space: SearchSpace
    screened: tuple[Screened, ...]
    verified: dict[int, VerifyScore]
    select_design: Design
    select_screened: Screened  # select's pick, screened like the candidates (index -1)
    select_score: VerifyScore | None
    pareto: tuple[int, ...]
    chosen: int | None
    design: Design | None
    reasons: tuple[str, ...]
    binding: tuple[str, ...]
    closest: int | None  # feasible candidate closest to the target at small strain
    wave: WaveChoice | None = None  # the chosen net's waves (deformation objective)

    def objective_value(self, i: int) -> float:
        """The ranked objective of candidate i: solver mismatch, or membrane-law error."""
        if self.objective == "deformation":
            return self.verified[i].mismatch
        return self.screened[i].error_rms_log


def candidate_design(ctx: SearchContext, point: NetPoint, base: Design) -> Design:
    """`base` (select's design: printer, cables) with the candidate's net."""
    sec = strand_section(ctx, point)
    net = NetDesign(material=point.material, print_style=ctx.style.key,
                    width_mm=round(ctx.width_mm, 6), height_mm=round(ctx.height_mm, 6),
                    mesh_x_mm=point.mesh_x_mm, mesh_y_mm=point.mesh_y_mm, strand=sec,
                    border_width_mm=round(point.border_beads * sec.bead_width_mm, 6),
                    pattern=point.pattern)
    return dataclasses.replace(base, net=net)


def design_point(ctx: SearchContext, d: Design) -> NetPoint:
    """The NetPoint (index -1) of a design's net, to screen it like the candidates."""
    n = d.net
    return NetPoint(-1, n.material, n.strand.beads_across, len(n.strand.layer_heights_mm),
                    round(2 * n.width_mm / n.mesh_x_mm), round(2 * n.height_mm / n.mesh_y_mm),
                    n.mesh_x_mm, n.mesh_y_mm, round(n.border_width_mm / n.strand.bead_width_mm),
                    n.pattern)


def stage_two(screened: list[Screened], nets: int) -> list[Screened]:
    """The candidates the solver verifies: the best printable net (lowest screening score) of
    each of the `nets` best material x section pairs, each with every border width."""
    feasible = sorted((s for s in screened if s.feasible),
                      key=rank_key)
    pairs: dict[tuple, tuple] = {}
    for s in feasible:
        pair = (s.point.material, s.point.beads_across, s.point.layers)
        if pair not in pairs and len(pairs) < nets:
            pairs[pair] = s.point.net_key
    keys = set(pairs.values())
    return sorted((s for s in feasible if s.point.net_key in keys), key=lambda s: s.point.index)


def pareto_indices(res_objective: str, screened: list[Screened],
                   verified: dict[int, VerifyScore]) -> tuple[int, ...]:
    """Candidates on the Pareto front of (objective, |dPi2|, |dPi3|, print time)."""
    if res_objective == "deformation":
        idx = sorted(verified)
        first = [verified[i].mismatch for i in idx]
    else:
        idx = [s.point.index for s in screened if s.feasible]
        first = [screened[i].error_rms_log for i in idx]
    if not idx:
        return ()
    vals = np.column_stack([first, [abs(screened[i].d_pi2) for i in idx],
                            [abs(screened[i].d_pi3) for i in idx],
                            [screened[i].print_time_s for i in idx]])
    return tuple(int(i) for i, k in zip(idx, pareto_mask(vals), strict=True) if k)


def _choose(objective: str, screened: list[Screened], verified: dict[int, VerifyScore]
            ) -> int | None:
    """The lowest objective (the screen's score includes select's datasheet penalty; the
    reasons flag a datasheet law); ties to the lower index."""
    if objective == "deformation":
        pool = [(v.mismatch, i) for i, v in verified.items()]
    else:
        pool = [(s.score, s.point.index) for s in screened if s.feasible]
    return min(pool)[1] if pool else None


def screen_all(runner: Runner, ctx: SearchContext, points: list[NetPoint]) -> list[Screened]:
    """Stage 1 over every point, batched for the runner's workers, in point order."""
    parts = runner.map(screen_batch, batches(points, runner.workers), shared=ctx,
                       label=f"1:{ctx.targets.scale:g} screening {len(points)} nets")
    return [s for part in parts for s in part]


def search(p: Prototype, scale: float, runner: Runner, *, objective: str = "deformation",
           space: SearchSpace | None = None, printer: str | None = None,
           verifier: Verifier | None = None, verify_nets: int = VERIFY_NETS,
           level_step: float | None = None,
           prototype_sweep: Callable[[VerifyShared, Design], Any] | None = None,
           wave_sweep: Callable[[VerifyShared, SolverBatch], list[Trial]] | None = None
           ) -> SearchResult:
    """Run the search at 1:`scale` on `runner`. `verifier` is required for `deformation`;
    `prototype_sweep` makes the prototype's sweep once, before the verifier's tasks share it
    (the prototype is the same for every candidate); `wave_sweep`: the wave stage's solver
    task (None: no wave stage)."""
    if objective not in OBJECTIVES:
        raise InputError(f"objective {objective!r} is not one of {', '.join(OBJECTIVES)}")
    if objective == "deformation" and verifier is None:
        raise InputError("the deformation objective needs the solver stage (a verifier)")
    if verify_nets < 1:
        raise InputError(f"verify_nets = {verify_nets} must be >= 1")
    t = scale_targets(p, scale)
    space = space or default_space(p, t)
    ctx = search_context(p, t, space, printer=printer)
    base = make_design(p, t, select(p, t, printer=ctx.printer.key))
    if base.net.material not in space.materials:  # to screen select's pick like the others
        ctx = dataclasses.replace(ctx, materials=ctx.materials + (
            load_material(base.net.material),))
    screened = screen_all(runner, ctx, grid(ctx, space))
    verified: dict[int, VerifyScore] = {}
    select_score = None
    if objective == "deformation":
        picks = stage_two(screened, verify_nets)
        tasks = [VerifyTask(str(s.point.index), candidate_design(ctx, s.point, base))
                 for s in picks] + [VerifyTask(SELECT_KEY, base)]
        shared = VerifyShared(p, level_step)
        if prototype_sweep is not None:
            shared = dataclasses.replace(shared, prototype_run=prototype_sweep(shared, base))
        parts = runner.map(verifier, solver_batches(tasks), shared=shared,
                           label=f"1:{t.scale:g} verifying {len(tasks)} nets (solver)")
        scores = [v for part in parts for v in part]
        verified = {int(v.key): v for v in scores if v.key != SELECT_KEY}
        select_score = next(v for v in scores if v.key == SELECT_KEY)
    chosen = _choose(objective, screened, verified)
    closest, binding = binding_constraints(screened, space)
    design = None if chosen is None else candidate_design(ctx, screened[chosen].point, base)
    wave = None
    if objective == "deformation" and wave_sweep is not None and chosen is not None and design:
        task = wave_sweep  # `shared` as the candidates had it: the one prototype sweep

        def sweep(tasks: list[WaveTask]) -> list[Trial]:
            jobs = solver_batches(tasks)
            parts = runner.map(task, jobs, shared=shared,
                               label=f"1:{t.scale:g} sweeping {len(tasks)} waved nets (solver)")
            return in_task_order(tasks, jobs, parts)

        ranked = sorted((s for s in screened if s.feasible), key=rank_key)
        def ratios(fn: Callable[[Any, Any], float], items: list[Any]) -> list[float]:
            return runner.map(fn, items, label=f"1:{t.scale:g} solving {len(items)} nets' "
                              "softest waves")

        wave = wave_stage(design, ((candidate_design(ctx, s.point, base), s.error_across)
                                   for s in ranked), space, sweep, ratios)
        design = wave.design(design)
    res = SearchResult(p.name, t.scale, objective, space, tuple(screened), verified, base,
                       screen_batch(ctx, [design_point(ctx, base)])[0], select_score,
                       pareto_indices(objective, screened, verified), chosen, design,
                       (), binding, closest, wave)
    waves = () if wave is None else (wave.sentence(),)
    return dataclasses.replace(res, reasons=(*choice_reasons(res), *waves,
                                             *target_sentence(screened)))
