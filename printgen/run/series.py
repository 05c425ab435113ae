"""`printgen series`: the virtual scale series of a prototype (printgen.verification.series)
run serially or on the executor's runner (printgen.executor, as the design search),
summarised (series_table) and written as one folder (`outputs.staged_dir`: whole or nothing,
locked, with its manifest):

- report.html: the sentences, the figure, the table, the law check, the assumptions;
- report.json: every number of the series (points, curves, law check, assumptions);
- series.csv: the table; figures/01-scale-series.png and .svg;
- timings.json: the wall-clock times (the one file that differs between identical runs):
  the estimate, the cases, the run up to the folder's writing (figure and report included),
  and, run from the command line, the process's own ("wall": interpreter start-up and
  imports too, what its user waits for).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from printgen.barrier.loads import get_load
from printgen.errors import InputError
from printgen.executor import open_runner
from printgen.executor.start import warm_up
from printgen.inputs.profiles import search_dirs
from printgen.inputs.prototype import Prototype, load_prototype
from printgen.outputs import TIMINGS, check_destination, write_folder
from printgen.outputs.display import Shown, Summary
from printgen.report.jsonout import dumps
from printgen.report.plots import load_pyplot
from printgen.report.series import series_csv, series_figure, series_report
from printgen.run.budget import DEFAULT_LIMIT_S, check_series_budget, run_cores
from printgen.run.options import RunOptions
from printgen.run.provenance import process_seconds, provenance_record
from printgen.run.shown import series_summary
from printgen.scene.scenes import SENSOR_FORCE_N
from printgen.verification.preprint import levels
from printgen.verification.series import (
    LEVEL,
    LEVEL_STEP,
    PROTOTYPE,
    CaseResult,
    NetOptions,
    SeriesShared,
    base_scene,
    cases,
    check_scales,
    rows_for,
    same_case,
    solve_case,
    solve_cold,
    starts_cold,
)
from printgen.verification.series_table import Series, summarise

PARALLEL_FROM = 12  # cases from which the series runs on this machine's workers by default
# what the cases import in a worker: a fork server imports it once, while the inputs are read
# (printgen.executor.start.warm_up; workers forked from this process have it already)
JOB_MODULES = ("printgen.verification.series",)


@dataclass(repr=False)
class SeriesRun(Shown):
    """What `printgen series` computed, where it ran and what it wrote."""

    series: Series
    results: list[CaseResult]
    where: str
    record: dict = field(default_factory=dict)
    files: list[str] = field(default_factory=list)

    def summary(self) -> Summary:
        return series_summary(self)


def run_series(prototype: str | Path | Prototype, scales: list[float], *,
               materials: tuple[str, ...] = (), net: NetOptions | None = None,
               level: float = LEVEL, level_step: float = LEVEL_STEP,
               out: str | Path | None = None, options: RunOptions | None = None,
               progress: Callable[[str], None] | None = None, bar: bool = False) -> SeriesRun:
    """Check every input, solve every (row, lambda) case, summarise, write `out` (if given).

    `options` (`RunOptions`): the load case, where the cases run and whether `out` may be
    replaced. `options.serial` None: serially up to PARALLEL_FROM cases, in parallel from
    there (a `scheduler` address or `workers` always mean parallel); the numbers are the same
    either way.
    """
    say = progress or (lambda _text: None)
    t0 = time.perf_counter()
    options = options or RunOptions()
    load, force, serial = options.load, options.force, options.serial
    scheduler, workers = options.scheduler, options.workers
    lams = check_scales(scales)
    if serial and (workers is not None or scheduler):
        raise InputError("--serial runs in this process: leave out --workers/--scheduler, or "
                         "--serial")
    p = prototype if isinstance(prototype, Prototype) else load_prototype(prototype)
    inputs = [p.path, *search_dirs()] if p.path else list(search_dirs())
    if out is not None:
        check_destination(Path(out), force=force, inputs=inputs)  # before any solve
    rows = tuple(rows_for(p, materials))
    shared = SeriesShared(p, rows, get_load(load).spec, net or NetOptions(), level, level_step)
    todo = cases(shared, lams)
    if serial is None:
        serial = len(todo) < PARALLEL_FROM and scheduler is None and workers is None
    if not serial and scheduler is None and workers != 1:
        warm_up(JOB_MODULES)
    limit = DEFAULT_LIMIT_S if options.time_limit_s is None else options.time_limit_s
    estimate, _ = check_series_budget(  # before the net is even built
        p, len(todo), limit_s=limit, cores=run_cores(serial, workers),
        levels=len(levels(step=level_step, top=level)), similar=similar_cases(shared, todo))
    base = base_scene(shared)  # geometry errors now, not in a worker
    say(f"{len(todo)} cases ({len(rows)} rows x {len(lams)} scales)"
        + ("" if serial else ", starting the workers"))
    meta: dict = {}

    def meanwhile() -> None:  # the folder's needs that do not wait for the cases
        load_pyplot()
        meta.update(provenance_record(options.command, prototype=p.path))

    t_cases = time.perf_counter()
    with open_runner(scheduler=scheduler, workers=workers, serial=serial,
                     progress=bar) as runner:
        results = solve_cases(runner, shared, todo, None if out is None else meanwhile)
        where = runner.where
    t_cases = time.perf_counter() - t_cases
    scene = "simple-free-top" if not base.cables else f"border cables, {base.mounting}"
    s = summarise(shared, lams, results, scene)
    s.assumptions = [*scene_assumptions(base, shared.net), *scaling_assumptions(shared)]
    record = {**s.to_record(), "load_case": shared.load, "ran_on": where, "level": level,
              "level_step": level_step, "solver_net": shared.net.to_record(),
              "curves": [{"row": r.row, "scale": r.scale, "levels": r.levels,
                          "values": r.curves} for r in results]}
    run = SeriesRun(s, results, where, record)
    if out is not None:
        say("writing the report")
        files = series_files(run)
        timings = {"estimate": estimate, "cases": t_cases, "cases_count": len(todo),
                   "total": time.perf_counter() - t0}
        wall = process_seconds() if options.command is not None else None
        if wall is not None:  # the command line's process: its start-up and imports too
            timings["wall"] = wall
        run.files = write_folder(Path(out), {**files, TIMINGS: dumps({"timings_s": timings})},
                                 force=force, volatile=(TIMINGS,), inputs=inputs, meta=meta)
    return run


def similar_cases(shared: SeriesShared, todo: list[tuple[str, float]]) -> int:
    """The cases that are the prototype scaled exactly (the similitude row: its answer is
    the prototype's, scaled) or another case's scene (`same_case`): the estimate does not
    count them. The sensors' wires on the models (1 N at every scale) break the similitude."""
    return sum(1 for c in todo if c != PROTOTYPE and (
        same_case(shared, c) is not None or (c[0] == "similitude" and not shared.net.sensors)))


def solve_cases(runner, shared: SeriesShared, todo: list[tuple[str, float]],
                meanwhile: Callable[[], None] | None = None) -> list[CaseResult]:
    """Every case of `todo`, in its order, on `runner`: the prototype first, then the other
    cases that start cold (`starts_cold`), the longest first; then the others from the
    prototype's states, the longest first, queued as soon as the prototype is solved
    (`Runner.map_then`: they fill the cores the cold cases leave); each case whose scene is
    another's (`same_case`) takes that one's result under its own row. `meanwhile` (work of
    this process that needs no case) runs in a thread beside the cases when they run in other
    processes (once those are started: a process forking its workers runs no other thread),
    else after them; its error is raised here."""
    own = sorted((c for c in todo if same_case(shared, c) is None),
                 key=lambda c: _work_rank(shared, c))  # the longest first: an even finish
    first = [PROTOTYPE, *(c for c in own if starts_cold(shared, c) and c != PROTOTYPE)]
    rest = [c for c in own if c not in first]
    aside = ThreadPoolExecutor(max_workers=1) if meanwhile and runner.workers > 1 else None
    chores = []

    def then(prototype: tuple[CaseResult, dict]) -> tuple[Callable, list, SeriesShared]:
        if aside is not None and meanwhile is not None:
            chores.append(aside.submit(meanwhile))
        return solve_case, rest, dataclasses.replace(shared, start=prototype[1])

    try:
        cold, warm = runner.map_then(solve_cold, first, then, shared=shared,
                                     label="series cases")
    finally:
        if aside is not None:
            aside.shutdown(wait=True)
    for f in chores:
        f.result()
    if meanwhile is not None and aside is None:
        meanwhile()
    done = {c: r for c, (r, _) in zip(first, cold, strict=True)}
    done.update(zip(rest, warm, strict=True))
    return [done[c] if c in done else
            dataclasses.replace(done[same_case(shared, c) or c], row=c[0], scale=c[1])
            for c in todo]


def _work_rank(shared: SeriesShared, case: tuple[str, float]) -> tuple[int, float]:
    """Sort key of the cases, the most Newton iterations first: the unscaled row (stiffer
    against its load as lambda grows: 82 to 115 iterations on the paper's series), then the
    materials (28 to 47), the largest lambda first; the similar cases last (they start at
    their answer)."""
    kind = next(r.kind for r in shared.rows if r.key == case[0])
    similar = kind == "similitude" and not shared.net.sensors
    return (2 if similar else 0 if kind == "unscaled" else 1, -case[1])


def scene_assumptions(base, net: NetOptions) -> list[tuple[str, str, str]]:
    """The prototype scene's rows, its sensor row saying that the models' wires pull when
    they do (the prototype's scene only reads them)."""
    rows = list(base.assumptions)
    if net.sensors:
        rows = [(w, v.replace("read only (no sensors on a field barrier)",
                              f"{SENSOR_FORCE_N:g} N along each wire on the models (lambda > 1), "
                              "read only on the prototype (lambda = 1)"), src)
                if w == "sensor wires" else (w, v, src) for w, v, src in rows]
    return rows


def scaling_assumptions(shared: SeriesShared) -> list[tuple[str, str, str]]:
    """The series' own modelling choices, one row each."""
    paper = "Lambert et al. 2023 (Fig. 2: the scale series)"
    p = shared.prototype
    mats = [r for r in shared.rows if r.kind == "material"]
    out = [("scaling", ("every length / lambda (nodes, mesh, strand and cable diameters), so "
            "sections / lambda^2; loads by Froude: A* / lambda^2, velocity / sqrt(lambda); the "
            "hold of unloaded nodes / lambda^2 (a share of rho g A*)"), paper),
           ("row: prototype material unscaled", ("the prototype's laws with E A / lambda^2 "
            "(same E, the Froude-only practice)"), paper),
           ("row: E / lambda", ("every law's force slope / lambda^3 (similitude: E A like every "
            "force)"), paper)]
    if mats:
        sec = f"net d = {p.net.strand_diameter * 1e3:g} mm / lambda"
        if p.border is not None:
            sec += f", cables d = {p.border.diameter * 1e3:g} mm / lambda"
        law = "" if p.net.panel_law is None else "; the prototype's panel law is replaced"
        out.append(("rows: materials", (f"E of the profile on the prototype's sections scaled "
                    f"({sec}), linear, tension-only{law} (not select's section: the series "
                    "isolates the material)"), "; ".join(r.source for r in mats)))
    out.append(("reading", (f"at h / h_B = {shared.level:g}, reached in steps of "
                f"{shared.level_step:g} (warm-started)"), paper))
    sensors = ("three 1 N wires pulling on every model (lambda > 1): a force that does not "
               "scale" if shared.net.sensors else "wires read only (they pull nothing)")
    out.append(("sensors", sensors, "--solver-net sensors=on|off"))
    o = shared.net
    out.append(("solver net", (f"water pressure {o.pressure} ('flow': along the flow, 'normal': "
                f"normal to the deformed net), initial slack {o.slack:.1%} of every strand and "
                f"cable, panel law read along its {o.orientation} diagonal (if any), mounting "
                f"{o.mounting or 'of the file'}"),
                "--solver-net (defaults: the prototype's scene)"))
    out.append(("prototype reference", ("the prototype row at lambda = 1 (its own material); "
                "ratio = value / reference"), "printgen"))
    return out


def series_files(run: SeriesRun) -> dict[str, str | bytes]:
    """The folder's files but timings.json, by path: the report, its JSON, the table, the
    figure (`write_folder` stages them and swaps them in whole, with the manifest)."""
    fig = series_figure(run.series)
    rep = series_report(run.series, fig)
    files: dict[str, str | bytes] = {"report.html": rep.html(), "report.json": dumps(run.record),
                                     "series.csv": series_csv(run.series)}
    for f in rep.figures:
        files[f"figures/01-{f.name}.png"], files[f"figures/01-{f.name}.svg"] = f.png, f.svg
    return files
