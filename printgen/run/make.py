"""`printgen make`: prototype + lambda -> targets, selection, design, printable parts, slicer
profiles, direct G-code, verification, report; every file staged and moved into the output
directory only when every step succeeded (a failed run leaves the previous outputs intact).

Steps are plain functions `step(ctx, stage)` (printgen.run.steps) run in order; each adds
files under `stage` and returns its records, which `make` puts into report.json. The verification, the longest and needing
nothing from the others, starts in a worker process at the beginning and its step collects it.
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
from printgen.design.design_file import load_design
from printgen.design.plan import make_design
from printgen.design.record import Design
from printgen.design.selection import Selection, design_net, select
from printgen.design.similitude import ScaledTargets, scale_targets
from printgen.errors import TimeLimitError
from printgen.executor.local import Helper, check_deadline, deadline, helper
from printgen.executor.signals import signals_deferred
from printgen.executor.start import cores, quiet_tracker, warm_up
from printgen.inputs.profiles import search_dirs
from printgen.inputs.prototype import Prototype, load_prototype
from printgen.outputs import MANIFEST, TIMINGS, check_destination, staged_dir
from printgen.report.extras import report_files
from printgen.report.html import Report
from printgen.report.jsonout import dumps
from printgen.report.parts_report import provenance_section
from printgen.report.report import design_record, design_sections
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
    split_timings,
)
from printgen.run.steps import (
    gcode_step,
    kit_step,
    parts_step,
    preload_parts,
    slicer_step,
    timed,
    verification_sweeps,
    verify_step,
)
from printgen.trace import span

log = logging.getLogger(__name__)
# what the workers' jobs import (the verification's sweeps, the report's figures): a fork
# server imports them once (printgen.executor.start.warm_up); matplotlib's pyplot is imported
# by the helper while its sweeps run (`verification_sweeps`), not here: the helper would wait
# for it
JOB_MODULES = ("printgen.run.steps", "printgen.verification.pooled", "printgen.report.plots")


@dataclass
class MakeContext:
    """What the steps share: inputs, the chosen design, the report being built; `record`
    holds the steps' returned records (written by `make` only)."""

    prototype: Prototype
    targets: ScaledTargets
    selection: Selection
    design: Design
    report: Report
    options: RunOptions = field(default_factory=RunOptions)
    record: dict[str, Any] = field(default_factory=dict)
    files: list[str] = field(default_factory=list)
    progress: Callable[[str], None] | None = None  # a step's finer progress (STEP per part)
    background: dict[str, Future] = field(default_factory=dict)  # jobs running in `helper`
    helper: Helper | None = None  # the helper process of the run (`verification_ahead`)
    toolpaths: dict[str, Any] = field(default_factory=dict)  # per part, built once per run
    volumes_mm3: dict[str, float] = field(default_factory=dict)  # per part's mesh (parts step)


Step = Callable[[MakeContext, Path], dict[str, Any]]  # its records, by report.json key


def plan(prototype_path: str | Path, scale: float, *,
         options: RunOptions | None = None) -> MakeContext:
    """Targets, selection and design: the fast, file-free part of `make`."""
    options = options or RunOptions()
    proto = load_prototype(prototype_path)
    t = scale_targets(proto, scale)
    sel = select(proto, t, printer=options.printer)
    design = make_design(proto, t, sel)
    design_file, own = options.design_file, None
    if design_file:  # the net of `printgen design` (its design.json) instead of select's
        design = load_design(design_file, scale=t.scale)
        own = design_net(proto, t, design.net, design.printer)
    rep = Report(f"printgen: {proto.name} at 1:{t.scale:g}")
    shown = Path(design_file).name if design_file else None
    design_sections(rep, proto, t, sel, design, design_file=shown, own_net=own)
    ctx = MakeContext(proto, t, sel, design, rep, options)
    ctx.record.update(design_record(proto, t, sel, design))
    if shown:
        ctx.record["design_file"] = shown
        ctx.record["design_net"] = own.to_record()  # its own stiffness error, not select's
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
        ctx = plan(prototype_path, scale, options=options)
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
                    ctx.record.update(step(ctx, stage))
                check_deadline(label)
            except TimeLimitError as exc:
                raise TimeLimitError(time_limit_line(label, exc, est, bound, t0)) from exc
            times = ctx.record.setdefault("timings_s", {})
            times[label] = time.perf_counter() - t
            times.setdefault("cpu_s", {})[label] = time.process_time() - cpu  # this process
        with span("make: report files"):
            write_report(ctx, stage, meta)
        if ctx.options.pdf:
            report_pdf(ctx, stage, progress)
        ctx.record["files"] = sorted([*ctx.files, "report.html", "report.json", "design.json",
                                      MANIFEST, TIMINGS])
        ctx.record.setdefault("timings_s", {})["total"] = time.perf_counter() - t0
        stable, timings = split_timings(ctx.record)
        (stage / "design.json").write_text(dumps(ctx.design.to_dict()))
        (stage / "report.json").write_text(dumps(stable))
        (stage / TIMINGS).write_text(dumps(timings))
    log.info("make finished in %.2f s", time.perf_counter() - t0)
    return ctx


def write_report(ctx: MakeContext, stage: Path, meta: dict[str, Any]) -> None:
    """The provenance section, the report's files (figures, lab files) and report.html."""
    meta.update(provenance(ctx))
    provenance_section(ctx.report, meta)
    for name, data in report_files(ctx.record, ctx.report).items():
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
    skipped = print_pdf(stage / "report.html", stage / "report.pdf")
    if skipped:
        log.warning("%s", skipped)
        ctx.record["pdf_skipped"] = skipped
    else:
        ctx.files.append("report.pdf")


@contextlib.contextmanager
def verification_ahead(ctx: MakeContext, steps: list[tuple[str, Step]]) -> Iterator[None]:
    """Start the verification's sweeps (`verification_sweeps`) in a helper process now, so
    that they run while the parts are built here; `sweeps_done` and `verify_step` collect
    them (a long run's per-level progress comes from the sweeps' workers straight to this
    process: printgen.executor.local). Only on 2 cores or more: on one there is nothing to gain."""
    serial = os.environ.get("PRINTGEN_SERIAL") or cores() < 2
    if serial or not any(s is verify_step for _, s in steps):
        yield
        return
    quiet_tracker()
    with helper() as h:
        ctx.helper = h
        ctx.background["verification sweeps"] = ctx.helper.submit(
            timed, verification_sweeps, ctx.prototype, ctx.design, ctx.options)
        try:
            with signals_deferred():  # a signal meanwhile would be lost in trimesh's imports
                preload_parts()
            yield
        finally:
            ctx.background.clear()
            ctx.helper = None


def size_check(ctx: MakeContext, verifies: bool) -> Estimate:
    """Estimate the run before any of it is done; InputError when it is over the limit
    (options.time_limit_s, default about a minute on 2 cores)."""
    limit = ctx.options.time_limit_s
    est = check_budget(ctx.prototype, ctx.design, cores=sweep_cores(),
                       limit_s=DEFAULT_LIMIT_S if limit is None else float(limit),
                       work=Work(sweep=verifies, cases=swept_cases(ctx.options)))
    ctx.record["size"] = est.to_record()
    ctx.record.setdefault("timings_s", {}).update(
        {"estimate": est.seconds, "estimate_verification": est.verification_s,
         "estimate_parts": est.parts_s, "estimate_speed_factor": est.speed})
    return est


def swept_cases(options: RunOptions) -> int:
    """Load cases the verification sweeps: its own and each other one of --loads."""
    own = get_load(options.load).spec
    return 1 + sum(spec != own for spec in distinct_specs(options.loads))


def run_bound(options: RunOptions) -> float | None:
    """Seconds after which the run stops: --time-limit when given. Without it a run is only
    refused when estimated over DEFAULT_LIMIT_S, never stopped: a shared machine can run
    many times slower than the estimate (the 1:40 example, estimated at 7 s, took 6 min
    under a load of 20 on 2 cores), and a run that does finish should not be lost."""
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
