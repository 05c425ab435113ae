"""`printgen design`: the design search at one scale or a series of scales, with the solver
stage wired in, and its output folder.

The search (`printgen.search.nets`) screens the candidates by the analytic membrane law and
verifies the best few with the pre-print verification (`printgen.verification.preprint`); the solver
task lives here because the verification stage sits above the search stage. Output folder (written
whole, `outputs.staged_dir`):

- report.json: per scale the chosen net and the reasons, the Pareto set, the verified nets,
  select's pick with its mismatch, the binding constraints; and the scale-series table;
- candidates.json: every candidate of every scale (one row per line);
- design.json (the chosen net at the main scale) and design-1-<lambda>.json per scale: what
  `printgen make --design FILE` prints;
- pareto-1-<lambda>.png: objective against |dPi2|, |dPi3| and print time;
- timings.json: the run's estimate and the search's wall time, s (the one file that differs
  between identical runs).
"""

from __future__ import annotations

import contextlib
import math
import os
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from printgen.executor import open_runner
from printgen.inputs.profiles import search_dirs
from printgen.inputs.prototype import Prototype, load_prototype
from printgen.outputs import TIMINGS, check_destination, write_folder
from printgen.outputs.display import Shown, Summary
from printgen.report.jsonout import dumps
from printgen.run.budget import DESIGN_LIMIT_S, check_design_budget, run_cores
from printgen.run.options import RunOptions
from printgen.run.provenance import provenance_record
from printgen.run.shown import design_summary
from printgen.run.wave_sweep import wave_batch
from printgen.scaling.record import Design
from printgen.scaling.similitude import ScaledTargets, scale_targets
from printgen.search.nets import (
    SearchResult,
    SolverBatch,
    VerifyScore,
    VerifyShared,
    VerifyTask,
    search,
)
from printgen.search.per_material import reachable
from printgen.search.record import candidates_json, result_record
from printgen.search.space import (
    SearchSpace,
    check_level_step,
    check_size,
    default_space,
    half_cell_counts,
    space_factors,
)
from printgen.search.waves import WAVES_VERIFIED


class Earlier:
    """The converged states of a batch's earlier sweeps (level -> displacements each), as a
    later sweep's `paths` (`solver.solve_path`: each earlier sweep's load step shifted onto
    the later one, a start, never the answer)."""

    def __init__(self) -> None:
        self.kept: list[dict[float, Any]] = []

    def add(self, states: dict[float, Any] | None) -> None:
        if states:
            self.kept.append(states)

    def __call__(self, level: float) -> list[Any]:
        """Each earlier sweep's state at `level`, None where it has none (one entry per
        sweep, in one order at every level: `solve_path` pairs them across levels)."""
        return [s.get(float(level)) for s in self.kept]

    @property
    def paths(self) -> Earlier | None:
        """Itself once a sweep is kept (None before: a cold start)."""
        return self if self.kept else None


def verify_batch(shared: VerifyShared, batch: SolverBatch) -> list[VerifyScore]:
    """Solver stage of the search: the verification of each design of `batch` (nets of one
    graph), as scores, against the prototype's sweep the search made once (`prototype_sweep`;
    without it, swept here once for the batch: it does not depend on the net). Each model sweep
    after the first also starts every load level from the batch's earlier sweeps' load steps
    to it, shifted onto its own path (`sweep`'s paths: the solver keeps the start of lowest
    potential and iterates to SOLVER_TOL, so the score is the cold sweep's to the solver
    tolerance, in fewer iterations), each factorized by the backend of a load path
    (`solver.driver.path_backend`, as every sweep). Pure: the same batch gives the same
    scores in any process (the sweep worker runs it serially)."""
    from threadpoolctl import threadpool_limits

    from printgen.verification.preprint import verify_plan

    lv = search_levels(shared)
    proto = shared.prototype_run
    earlier = Earlier()  # the earlier designs' states
    out = []
    with _serial(), threadpool_limits(limits=1):  # one BLAS thread: the same sums everywhere
        for task in batch.tasks:
            plan = verify_plan(shared.prototype, task.design, lv=lv, sensors=False,
                               prototype=None if proto is None else proto.scene)
            if proto is None:  # the model alone is compared: the sensors' share is not scored
                fn, args, kw = plan.jobs()[1]
                proto = fn(*args, **kw)
            fn, args, kw = plan.jobs()[0]
            model = fn(*args, **kw, keep_states=True, paths=earlier.paths)
            earlier.add(model.states)
            out.append(_score(task.key, plan.verified(model, proto), model))
    return out


def verify_task(shared: VerifyShared, task: VerifyTask) -> VerifyScore:
    """The verification of one design as a score (`verify_batch` of it alone: a cold sweep)."""
    return verify_batch(shared, SolverBatch((task,)))[0]


def _score(key: str, v: Any, model: Any) -> VerifyScore:
    """A Verification's score: the RMS over the metrics of their RMS mismatches (and the
    model sweep's work)."""
    rms = math.sqrt(sum(m.rms_rel**2 for m in v.mismatches) / len(v.mismatches))
    failed = sorted(set(v.prototype.failed) | set(v.model.failed))
    return VerifyScore(key, rms, {m.metric: m.rms_rel for m in v.mismatches},
                       max(m.max_rel for m in v.mismatches), v.ok, tuple(failed),
                       int(sum(model.iterations)), model.cpu_s)


def search_levels(shared: VerifyShared) -> Any:
    """The load levels of the search's sweeps (None: the verification's own)."""
    from printgen.verification.preprint import levels

    return None if shared.level_step is None else levels(step=shared.level_step)


def prototype_sweep(shared: VerifyShared, design: Design) -> Any:
    """The prototype's sweep as `verify` makes it beside `design` (at the search's levels),
    once per search: it does not depend on the candidate net."""
    from threadpoolctl import threadpool_limits

    from printgen.verification.preprint import verify_plan

    plan = verify_plan(shared.prototype, design, lv=search_levels(shared))
    fn, args, kw = plan.jobs()[1]
    with threadpool_limits(limits=1):
        return fn(*args, **kw)


@contextlib.contextmanager
def _serial() -> Iterator[None]:
    """No nested process pool inside a sweep worker: the sweep already fills the cores."""
    old = os.environ.get("PRINTGEN_SERIAL")
    os.environ["PRINTGEN_SERIAL"] = "1"
    try:
        yield
    finally:
        if old is None:
            os.environ.pop("PRINTGEN_SERIAL", None)
        else:
            os.environ["PRINTGEN_SERIAL"] = old


@dataclass(frozen=True)
class SearchOptions:
    """The search's knobs (None: the default of `default_space`)."""

    objective: str = "deformation"
    materials: tuple[str, ...] | None = None
    mesh_x_mm: tuple[float, float] | None = None
    mesh_y_mm: tuple[float, float] | None = None
    mesh_tolerance: float | None = None
    border_beads: tuple[int, ...] | None = None
    printer: str | None = None
    verify_nets: int = 3
    level_step: float | None = None


@dataclass(repr=False)
class DesignRun(Shown):
    """The searches of one call, where they ran and what was written."""

    results: list[SearchResult]
    where: str
    record: dict = field(default_factory=dict)
    files: list[str] = field(default_factory=list)
    timings: dict = field(default_factory=dict)  # s: the estimate, the search (timings.json)

    def summary(self) -> Summary:
        return design_summary(self)


def space_for(p: Prototype, scale: float, o: SearchOptions) -> SearchSpace:
    kw = {k: v for k, v in (("materials", o.materials), ("mesh_x_mm", o.mesh_x_mm),
                            ("mesh_y_mm", o.mesh_y_mm), ("tolerance", o.mesh_tolerance),
                            ("border_beads", o.border_beads)) if v is not None}
    t = scale_targets(p, scale)
    space = default_space(p, t, **kw)
    check_level_step(o.level_step)
    check_size(space, *meshes_of(space, t))
    return space


def meshes_of(space: SearchSpace, t: ScaledTargets) -> tuple[int, int]:
    """How many meshes across and up the space holds at the targets' scale."""
    return (len(half_cell_counts(t["width"] * 1e3, space.mesh_x_mm)),
            len(half_cell_counts(t["height"] * 1e3, space.mesh_y_mm)))


def check_work(p: Prototype, spaces: dict[float, SearchSpace], o: SearchOptions,
               run: RunOptions) -> float:
    """The search's size against its time limit (`budget.check_design_budget`), before any
    work: every scale's nets screened, and with the deformation objective `verify_nets` of
    them (with every border), select's pick and the chosen net's best waves verified, each
    over the search's load levels. Returns the estimate (s)."""
    screened = sum(math.prod(space_factors(sp, *meshes_of(sp, scale_targets(p, s))))
                   for s, sp in spaces.items())
    verified = sum(o.verify_nets * len(sp.border_beads) + 1 + WAVES_VERIFIED
                   for sp in spaces.values()) \
        if o.objective == "deformation" else 0  # each net with every border, select's pick
    cores = run_cores(bool(run.serial), run.workers)
    limit = DESIGN_LIMIT_S if run.time_limit_s is None else run.time_limit_s
    from printgen.verification.preprint import levels

    lv = levels() if o.level_step is None else levels(step=o.level_step)
    return check_design_budget(p, screened, verified, limit_s=limit, cores=cores,
                               prototypes=len(spaces) if verified else 0, levels=len(lv))


def search_at_scales(prototype: str | Path | Prototype, scales: list[float], *,
                    options: SearchOptions = SearchOptions(),
                    run: RunOptions | None = None, progress: bool = False) -> DesignRun:
    """Search at every scale on one runner (`run`: this machine's workers, the Dask
    scheduler at `run.scheduler`, or serially)."""
    run = run or RunOptions()
    p = prototype if isinstance(prototype, Prototype) else load_prototype(prototype)
    t0 = time.perf_counter()
    spaces = {s: space_for(p, s, options) for s in scales}  # every bound checked before work
    estimate = check_work(p, spaces, options, run)
    results = []
    with open_runner(scheduler=run.scheduler, workers=run.workers, serial=bool(run.serial),
                     progress=progress) as runner:
        for s in scales:
            results.append(search(p, s, runner, objective=options.objective,
                                  space=spaces[s], printer=options.printer,
                                  verifier=verify_batch, verify_nets=options.verify_nets,
                                  prototype_sweep=prototype_sweep,
                                  level_step=options.level_step, wave_sweep=wave_batch))
        where = runner.where
    return DesignRun(results, where, design_record(p, results, options),
                     timings={"estimate": estimate, "search": time.perf_counter() - t0})


def design_record(p: Prototype, results: list[SearchResult], o: SearchOptions) -> dict:
    """The report.json of a call: every scale's record and the series table."""
    recs = {f"{r.scale:g}": result_record(r) for r in results}
    return {"prototype": p.name, "objective": o.objective,
            "level_step": o.level_step, "verify_nets": o.verify_nets,
            "scales": recs, "reachable": reachable(list(recs.values())),
            "series": [series_row(r) for r in results]}


def series_row(r: SearchResult) -> dict:
    """One line of the scale-series table: the best net at this scale."""
    if r.chosen is None:
        return {"scale": r.scale, "chosen": None, "binding_constraints": list(r.binding)}
    s = r.screened[r.chosen]
    v = r.verified.get(r.chosen)
    return {"scale": r.scale, "chosen": s.to_record(),
            "mismatch_rms": None if v is None else v.mismatch,
            "select_mismatch_rms": None if r.select_score is None else r.select_score.mismatch,
            "error_small_strain": s.error_small, "stiffness_error_across": s.error_across,
            "stiffness_error_up": s.error_up, "d_pi2": s.d_pi2, "d_pi3": s.d_pi3,
            "print_time_s": s.print_time_s, "binding_constraints": list(r.binding)}


def design_inputs(prototype: str | Path | Prototype) -> list:
    """The files and folders a design run reads (none may lie inside its --out)."""
    path = prototype.path if isinstance(prototype, Prototype) else prototype
    return [path, *search_dirs()]


def check_out(out: str | Path, prototype: str | Path | Prototype) -> None:
    """OutputError now, before the search, when `out` cannot take the run's folder."""
    check_destination(Path(out), force=False, inputs=design_inputs(prototype))


def write_outputs(run: DesignRun, out: str | Path, main_scale: float | None,
                  prototype: str | Path | Prototype | None = None,
                  command: list[str] | None = None) -> list[str]:
    """Write the folder (whole, atomically); returns the file names."""
    from printgen.report.design_plots import pareto_figure

    files: dict[str, str | bytes] = {"report.json": dumps(run.record),
                                     "candidates.json": candidates_json(run.results),
                                     TIMINGS: dumps({"timings_s": run.timings})}
    for r in run.results:
        if r.design is not None:
            text = dumps(r.design.to_dict())
            files[f"design-1-{r.scale:g}.json"] = text
            if main_scale is not None and r.scale == main_scale:
                files["design.json"] = text
        files[f"pareto-1-{r.scale:g}.png"] = pareto_figure(r)
    inputs = design_inputs(prototype) if prototype is not None else []
    path = prototype.path if isinstance(prototype, Prototype) else prototype
    run.files = write_folder(out, files, inputs=inputs, volatile=(TIMINGS,),
                             meta=provenance_record(command, prototype=path))
    return run.files
