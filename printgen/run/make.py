"""`printgen make`: prototype + lambda -> targets, selection, design, printable parts, slicer
profiles, direct G-code, verification, report; every file staged and moved into the output
directory only when every step succeeded (a failed run leaves the previous outputs intact).

Steps are plain functions `step(ctx, stage)` (printgen.run.steps) run in order; each adds
files under `stage` and returns its records (printgen.report.records), which `make` keeps
with the plan's; the report is built once from them at the end (printgen.report.build), and
report.json is their records. Wall-clock times go to the run's timings (timings.json) only.
The verification, the longest and needing nothing from the others, starts in a worker process
at the beginning, with the advice beside its band's variants, and its step collects them.
"""

from __future__ import annotations

import contextlib
import logging
import math
import os
import time
from collections.abc import Callable, Iterator
from concurrent.futures import Future
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from printgen.barrier.loads import distinct_specs, get_load
from printgen.errors import InputError, TimeLimitError
from printgen.executor.local import Helper, check_deadline, deadline, helper
from printgen.executor.signals import signals_deferred
from printgen.executor.start import cores, quiet_tracker, warm_up
from printgen.inputs.profiles import search_dirs
from printgen.inputs.prototype import Prototype, load_prototype
from printgen.outputs import MANIFEST, TIMINGS, check_destination, staged_dir
from printgen.outputs.display import Shown, Summary
from printgen.report.build import build_report, report_files
from printgen.report.html import Report
from printgen.report.jsonout import dumps
from printgen.report.records import PlanRecords, RunRecords
from printgen.run.budget import (
    DEFAULT_LIMIT_S,
    LONG_RUN_S,
    Estimate,
    Work,
    check_budget,
    level_bars,
    sweep_cores,
)
from printgen.run.options import RunOptions
from printgen.run.provenance import (  # noqa: F401 (json_output, TIME_KEYS: used via make)
    TIME_KEYS,
    json_output,
    provenance,
)
from printgen.run.shown import make_summary
from printgen.run.steps import (
    draw_figures,
    gcode_step,
    kit_step,
    parts_step,
    preload_parts,
    slicer_step,
    sweeps_and_advice,
    timed,
    verify_step,
)
from printgen.scaling.design_file import load_design
from printgen.scaling.plan import make_design
from printgen.scaling.record import Design
from printgen.scaling.selection import Selection, design_net, select
from printgen.scaling.similitude import ScaledTargets, scale_targets
from printgen.trace import span
from printgen.verification.bands import Band
from printgen.verification.preprint import Verification
from printgen.verification.tables import CurveTable

log = logging.getLogger(__name__)
# what the workers' jobs import (the verification's sweeps, the report's figures): a fork
# server imports them once (printgen.executor.start.warm_up); matplotlib's pyplot is imported
# by the helper while its sweeps run (`verification_sweeps`), not here: the helper would wait
# for it
JOB_MODULES = ("printgen.run.steps", "printgen.verification.pooled", "printgen.report.plots")


@dataclass(repr=False)
class MakeContext(Shown, CurveTable):
    """What the steps share: inputs, the chosen design, the run's records (`records`: the
    plan's and each step's, as objects) and `record`, their records as report.json holds
    them (written by `make` only); `timings`, the run's wall-clock times (timings.json);
    `report`, built from `records` once every step ran."""

    prototype: Prototype
    targets: ScaledTargets
    selection: Selection
    design: Design
    records: RunRecords
    options: RunOptions = field(default_factory=RunOptions)
    record: dict[str, Any] = field(default_factory=dict)
    timings: dict[str, Any] = field(default_factory=dict)
    report: Report | None = None
    files: list[str] = field(default_factory=list)
    progress: Callable[[str], None] | None = None  # a step's finer progress (STEP per part)
    background: dict[str, Future] = field(default_factory=dict)  # jobs running in `helper`
    helper: Helper | None = None  # the helper process of the run (`verification_ahead`)
    toolpaths: dict[str, Any] = field(default_factory=dict)  # per part, built once per run
    volumes_mm3: dict[str, float] = field(default_factory=dict)  # per part's mesh (parts step)
    out: Path | None = None  # the output folder (the advice's command names files in it)

    def summary(self) -> Summary:
        return make_summary(self)

    def curve_source(self) -> tuple[Verification, Band | None]:
        """The run's verification and its band; InputError when the run checked nothing."""
        check = self.records.check
        if check is None:
            raise InputError("this make run has no verification (its steps left it out)")
        return check.verification, check.band


Step = Callable[[MakeContext, Path], dict[str, Any]]  # its records, by report.json key


def plan_run(prototype_path: str | Path, scale: float, *,
             options: RunOptions | None = None) -> MakeContext:
    """The run's context: targets, selection and design, the fast, file-free part of `make`
    (`printgen.plan` gives only its `Design`)."""
    options = options or RunOptions()
    proto = load_prototype(prototype_path)
    t = scale_targets(proto, scale)
    sel = select(proto, t, printer=options.printer)
    design = make_design(proto, t, sel)
    design_file, own = options.design_file, None
    if design_file:  # the net of `printgen design` (its design.json) instead of select's
        design = load_design(design_file, scale=t.scale, prototype=proto)
        own = design_net(proto, t, design.net, design.printer)
    shown = Path(design_file).name if design_file else None
    planned = PlanRecords(proto, t, sel, design, design_file=shown, own_net=own)
    run = RunRecords(f"printgen: {proto.name} at 1:{t.scale:g}", design, plan=planned)
    ctx = MakeContext(proto, t, sel, design, run, options)
    ctx.record.update(planned.to_record())
    return ctx


def make(prototype_path: str | Path, scale: float, out: str | Path, *,
         steps: list[tuple[str, Step]] | None = None, options: RunOptions | None = None,
         progress: Callable[[str], None] | None = None) -> MakeContext:
    """Run every step into a stage folder and swap it in as the whole of `out`.

    `out` gets manifest.json (files, inputs, version, command line) and timings.json (the
    only file that differs between runs).
    """
    t0 = time.perf_counter()
    warm_up(JOB_MODULES)
    options = options or RunOptions()
    inputs = [prototype_path, options.design_file, *search_dirs()]
    check_destination(Path(out), force=options.force, inputs=inputs)  # fail fast
    with span("make: plan and estimate"):
        ctx = plan_run(prototype_path, scale, options=options)
        ctx.out = Path(out)
        est = size_check(ctx, steps is None or any(s is verify_step for _, s in steps))
    if progress and est.seconds > LONG_RUN_S:
        progress(f"estimate: {est.summary()}")
    meta: dict[str, Any] = {}
    long_run = progress if est.seconds > LONG_RUN_S else None  # per-level bars when long
    steps = steps if steps is not None else default_steps()
    ctx.progress = progress
    bound = run_bound(ctx.options)
    with deadline(None if bound is None else time.time() + bound - (time.perf_counter() - t0)), \
            staged_dir(out, force=ctx.options.force, meta=meta,
                       volatile=(TIMINGS,), inputs=inputs) as stage, level_bars(long_run), \
            verification_ahead(ctx, steps):
        for label, step in steps:
            if progress:
                progress(label)
            t, cpu = time.perf_counter(), time.process_time()
            try:
                with span(f"step: {label}"):
                    keep(ctx, step(ctx, stage))
                check_deadline(label)
            except TimeLimitError as exc:
                raise TimeLimitError(time_limit_line(label, exc, est, bound, t0)) from exc
            times = ctx.timings.setdefault("timings_s", {})
            times[label] = time.perf_counter() - t
            times.setdefault("cpu_s", {})[label] = time.process_time() - cpu  # this process
        try:
            with span("make: report files"):
                write_report(ctx, stage, meta)  # the figures are drawn here
        except TimeLimitError as exc:
            raise TimeLimitError(time_limit_line(REPORT, exc, est, bound, t0)) from exc
        if ctx.options.pdf:
            report_pdf(ctx, stage, progress)
        ctx.record["files"] = sorted([*ctx.files, "report.html", "report.json", "design.json",
                                      MANIFEST, TIMINGS])
        ctx.timings.setdefault("timings_s", {})["total"] = time.perf_counter() - t0
        (stage / "design.json").write_text(dumps(ctx.design.to_dict()))
        (stage / "report.json").write_text(dumps(ctx.record))
        (stage / TIMINGS).write_text(dumps(ctx.timings))
    log.info("make finished in %.2f s", time.perf_counter() - t0)
    return ctx


def keep(ctx: MakeContext, records: dict[str, Any]) -> None:
    """Keep a step's records (by report.json key) with the run's, and their records in
    `ctx.record`."""
    ctx.records.steps.update(records)
    ctx.record.update(ctx.records.records(records))


def write_report(ctx: MakeContext, stage: Path, meta: dict[str, Any]) -> None:
    """The report, built once from the run's records with their provenance (the manifest's),
    its figures drawn (`draw_figures`), its files (figures, lab files) and report.html;
    report.json's summary."""
    meta.update(provenance(ctx))
    ctx.records.provenance = meta
    with span("report: build"):
        ctx.report, summary = build_report(ctx.records)
    ctx.record["summary"] = summary.to_record()
    draw_figures(ctx)
    for name, data in report_files(ctx.records, ctx.report).items():
        (stage / name).parent.mkdir(exist_ok=True)
        (stage / name).write_bytes(data)
        ctx.files.append(name)
    (stage / "report.html").write_text(ctx.report.html())


def report_pdf(ctx: MakeContext, stage: Path, progress: Callable[[str], None] | None) -> None:
    """report.pdf from the written report.html (headless Chromium); without Chromium the
    one-line reason goes to ctx.record["pdf_skipped"] and the run goes on."""
    from printgen.report.pdf import print_pdf

    if progress:
        progress("report.pdf (headless Chromium)")
    skipped = print_pdf(stage / "report.html", stage / "report.pdf", ctx.options.paper)
    if skipped:
        log.warning("%s", skipped)
        ctx.record["pdf_skipped"] = skipped
    else:
        ctx.files.append("report.pdf")


@contextlib.contextmanager
def verification_ahead(ctx: MakeContext, steps: list[tuple[str, Step]]) -> Iterator[None]:
    """Start the verification's sweeps and the advice (`sweeps_and_advice`) in a helper
    process now, so that they run while the parts are built here; `sweeps_done` and
    `verify_step` collect them (a long run's per-level progress comes from the sweeps'
    workers straight to this process: printgen.executor.local). Only on 2 cores or more: on
    one there is nothing to gain."""
    serial = os.environ.get("PRINTGEN_SERIAL") or cores() < 2
    if serial or not any(s is verify_step for _, s in steps):
        yield
        return
    quiet_tracker()
    with helper() as h:
        ctx.helper = h
        ctx.background["verification sweeps"] = ctx.helper.submit(
            timed, sweeps_and_advice, ctx.prototype, ctx.design, ctx.options)
        try:
            with signals_deferred():  # a signal meanwhile would be lost in trimesh's imports
                preload_parts()
            yield
        finally:
            ctx.background.clear()
            ctx.helper = None


REPORT = "report (HTML, figures, lab files)"  # the last stage of a run, after its steps


def size_check(ctx: MakeContext, verifies: bool) -> Estimate:
    """Estimate the run before any of it is done; InputError when it is over the limit
    (options.time_limit_s, default about a minute on 2 cores)."""
    limit = ctx.options.time_limit_s
    est = check_budget(ctx.prototype, ctx.design, cores=sweep_cores(),
                       limit_s=DEFAULT_LIMIT_S if limit is None else float(limit),
                       work=Work(sweep=verifies, cases=swept_cases(ctx.options)))
    keep(ctx, {"size": est})
    ctx.timings.setdefault("timings_s", {}).update(
        {"estimate": est.seconds, "estimate_verification": est.verification_s,
         "estimate_parts": est.parts_s, "estimate_speed_factor": est.speed,
         "estimate_advice": est.advice_s})
    return est


def swept_cases(options: RunOptions) -> int:
    """Load cases the verification sweeps: its own and each other one of --loads."""
    own = get_load(options.load).spec
    return 1 + sum(spec != own for spec in distinct_specs(options.loads))


def run_bound(options: RunOptions) -> float | None:
    """Seconds after which the run stops: --time-limit when given. Without it a run is only
    refused when estimated over DEFAULT_LIMIT_S, never stopped: a shared machine can run
    many times slower than the estimate (benchmarks/measurements.md#make-no-default-stop), and
    a run that does finish should not be lost."""
    limit = options.time_limit_s
    return float(limit) if limit else None


def time_limit_line(label: str, cause: Exception, est: Estimate, bound: float | None,
                    t0: float) -> str:
    """The one line of a run stopped at its time limit: step (and what in it was running),
    estimate, time spent, option."""
    spent = time.perf_counter() - t0
    where = str(cause).removesuffix(": past the time limit")
    inside = f" ({where})" if where and where != label else ""
    return (f"stopped in step '{label}'{inside} after {spent:.0f} s, past the time limit of "
            f"{bound or 0:g} s (--time-limit); the run was estimated at about "
            f"{est.seconds:.0f} s; nothing written. "
            f"Raise it with --time-limit {math.ceil(max(spent, bound or 0) * 2 / 60) * 60:g}, or "
            "coarsen the nets")


def default_steps() -> list[tuple[str, Step]]:
    return [("meshes (STL, 3MF)", parts_step), ("slicer profiles", slicer_step),
            ("direct G-code", gcode_step), ("assembly and toolpath previews", kit_step),
            ("verification (prototype and model load sweeps)", verify_step)]
