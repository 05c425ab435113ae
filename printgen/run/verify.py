"""`printgen verify`: the pre-print check of an existing design (the design.json `make`
wrote), with its uncertainty band, and optionally a lab's measured loading test compared with
it and one factor of the printed net fitted to it. Output folder (written whole,
`outputs.staged_dir`): report.html, report.json, timings.json, the lab's CSV files
(printgen.report.labfiles), and with a stiffness fit `<material>-fitted.toml`, the profile
that feeds the fit back.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from printgen.executor.start import preload
from printgen.inputs.materials import load_material
from printgen.inputs.profiles import profile_name, search_dirs
from printgen.inputs.prototype import Prototype, load_prototype
from printgen.outputs import TIMINGS, check_destination, staged_dir
from printgen.outputs.display import Shown, Summary
from printgen.report.build import build_report, report_files
from printgen.report.jsonout import dumps
from printgen.report.records import CheckRecords, MeasuredRecords, RunRecords
from printgen.run.budget import (
    DEFAULT_LIMIT_S,
    FitPlan,
    Work,
    check_budget,
    fit_estimate,
    sweep_cores,
)
from printgen.run.options import RunOptions
from printgen.run.provenance import provenance_record
from printgen.run.shown import verify_summary
from printgen.scaling.design_file import load_design
from printgen.scaling.record import Design
from printgen.scaling.selection import design_net
from printgen.scaling.similitude import scale_targets
from printgen.scene.readings import design_units
from printgen.verification.bands import Band, band_verdicts, model_load_kw
from printgen.verification.decide import decide, excluded_by_data
from printgen.verification.fit import (
    MultiFit,
    all_choices,
    fit_levels,
    fit_measured,
    planned_sweeps,
    screen_coarsen,
)
from printgen.verification.measured import (
    FACTOR_EVALUATIONS,
    Fit,
    Measurement,
    fit_factor,
    fitted_profile,
    measured_path,
    model_predictor,
    read_measured,
)
from printgen.verification.pooled import verify_with_band
from printgen.verification.preprint import Verification, free_section
from printgen.verification.tables import CurveTable

# what the workers' jobs import (the sweeps, the figures): a fork server imports them once
JOB_MODULES = ("printgen.verification.pooled", "printgen.report.plots")


@dataclass(repr=False)
class VerifyRun(Shown, CurveTable):
    """What `printgen verify` computed and wrote: `record` is report.json's with the run's
    timings under "timings_s" (`--json`'s output); `records`, the objects it came from."""

    prototype: Prototype
    design: Design
    verification: Verification
    band: Band
    measurement: Measurement | None
    fit: Fit | None
    profile_text: str
    record: dict[str, Any]
    files: list[str]
    records: RunRecords | None = None

    def summary(self) -> Summary:
        return verify_summary(self)

    def curve_source(self) -> tuple[Verification, Band | None]:
        return self.verification, self.band


def verify_design(prototype: str | Path, scale: float, design_path: str | Path,
                  out: str | Path, *, measured: str | Path | None = None,
                  fit: str = "stiffness", options: RunOptions | None = None,
                  progress: Callable[[str], None] | None = None) -> VerifyRun:
    """Check the design against the prototype with its band; compare and fit `measured`.

    Every input is read and checked before the first solve, so a bad file costs nothing; so
    is the run's size (`printgen.run.budget`): InputError when its estimate passes
    `time_limit_s`.
    """
    say = progress or (lambda _label: None)
    t0 = time.perf_counter()
    options = options or RunOptions()
    load, force, time_limit_s = options.load, options.force, options.time_limit_s
    preload(JOB_MODULES)  # a fork server's imports, while the inputs are read
    inputs = [prototype, design_path, measured, *search_dirs()]
    check_destination(Path(out), force=force, inputs=inputs)  # before any work
    p = load_prototype(prototype)
    d = load_design(design_path, scale=scale, prototype=p)
    m = read_measured(measured, design_units(d)) if measured is not None else None
    limit = DEFAULT_LIMIT_S if time_limit_s is None else time_limit_s
    plan = fit_plan(d, m, fit, free_section(p)) if m is not None else None
    est = check_budget(p, d, limit_s=limit, cores=sweep_cores(),
                       work=Work(parts=False, fit=m is not None, model_follows=False,
                                 fit_plan=plan))
    load_kw = model_load_kw(p, d, load)
    say("verification (prototype and model load sweeps) and its uncertainty band (model "
        "variants)")
    v, band = verify_with_band(p, d, load=load, free_section=free_section(p))
    if m is not None:  # the variants the lab's own test contradicts leave the verdict
        band = dataclasses.replace(band, data_excluded=excluded_by_data(band, m))
        v = dataclasses.replace(v, decision=decide(v.prototype.deformation.values, band,
                                                   v.prototype_band))
    result, text = None, ""
    t_fit, cpu_fit = time.perf_counter(), time.process_time()
    if m is not None and fit == "multi":
        say(f"multi-parameter fit of the printed net to {Path(measured).name}")
        result = fit_measured(d, m, fit_levels(m), load_kw=load_kw, free_section=free_section(p))
        text = _multi_profile_text(d, result, Path(measured).name) if result.explains else ""
    elif m is not None:
        say(f"fit of the net's {fit} to {Path(measured).name}")
        one = fit_factor(m, model_predictor(d, band, m, fit, load_kw=load_kw), fit)
        # a factor at the end of its range, or one that does not improve every measured
        # column, explains nothing: no profile to feed back
        text = _profile_text(d, one, Path(measured).name) if one.writes_profile else ""
        result = one
    fit_s = time.perf_counter() - t_fit
    # the fit's CPU: its sweeps' in the workers (multi), else this process's (one factor)
    fit_cpu = result.cpu_s if isinstance(result, MultiFit) else time.process_time() - cpu_fit
    run = RunRecords(f"printgen verify: {p.name} at 1:{d.scale:g}", d)
    # the design's net scored like select's candidates: its stiffness across and up the barrier
    run.steps["design_net"] = design_net(p, scale_targets(p, d.scale), d.net, d.printer)
    run.steps["verification"] = CheckRecords(v, band, d.scale, nested=False)
    if m is not None:
        run.steps["measured"] = MeasuredRecords(m, band, result, text)
    rep, summary = build_report(run)
    rep.draw()  # the figures, side by side in worker processes
    record = {**run.to_record(), "summary": summary.to_record()}
    files = {"report.html": rep.html(), "report.json": dumps(record)}
    files.update({k: b.decode("utf-8") for k, b in report_files(run, rep, figures=False).items()})
    if text:
        files[fitted_name(d)] = text
    timings = {"total": time.perf_counter() - t0, "band": band.seconds,
               "estimate": est.seconds, "estimate_speed_factor": est.speed,
               **({"fit": fit_s, "fit_cpu": fit_cpu, "estimate_fit_sweeps": plan.sweeps,
                   "estimate_fit": fit_estimate(est)} if plan else {})}
    files[TIMINGS] = dumps({"timings_s": timings})
    meta = provenance_record(options.command, prototype=prototype,
                             files={"design_file": design_path, "measured": measured},
                             design=d, check=run.steps["verification"])
    written = _write(out, files, force, inputs, meta)
    return VerifyRun(p, d, v, band, m, result, text, {**record, "timings_s": timings}, written,
                     run)


def fit_plan(d: Design, m: Measurement, fit: str, section: float | None) -> FitPlan:
    """The sweeps the fit of `m` will run (`fit`: "multi" or a one-factor kind), for the
    run's estimate: their nets (mesh coarsening), counts and load levels."""
    levels = len(measured_path(m))
    if fit == "multi":
        plan = planned_sweeps(len(all_choices(section)))
        return FitPlan(((screen_coarsen(d), plan["coarse"]), (1, plan["fine"])), levels,
                       parallel=True)
    # the Brent search on the band's net, the nominal, and the nominal on the band's coarse
    # net when it has one; the design's own net assumed, as for the band's variants
    # (printgen.run.budget: a run whose band coarsens is estimated high)
    return FitPlan(((1, FACTOR_EVALUATIONS + 2),), levels, parallel=False)


def _multi_profile_text(d: Design, fit: MultiFit, source: str) -> str:
    """The profile of an explained multi-parameter fit: its net law factor (slack and the
    mounting choices belong to the test's installation, stated as comments)."""
    p = fit.params
    mat = load_material(d.net.material)
    law = mat.panel_law
    kappas = law.kappas if law is not None and law.has_geometry else None
    text = fitted_profile(d.net.material, "stiffness", p.net_factor, panel_kappas=kappas,
                          modulus_gpa=mat.modulus()[0] / 1e9, source=source)
    return (f"# installation fitted with it (not material): net slack {p.net_slack:.2%}, "
            f"cable slack {p.cable_slack:.2%}, mounting {p.mounting}, orientation "
            f"{p.orientation or 'as profiled'}\n" + text)


def _profile_text(d: Design, fit: Fit, source: str) -> str:
    mat = load_material(d.net.material)
    law = mat.panel_law
    kappas = law.kappas if law is not None and law.has_geometry else None
    return fitted_profile(d.net.material, fit.kind, fit.value, panel_kappas=kappas,
                          modulus_gpa=mat.modulus()[0] / 1e9, source=source)


def fitted_name(d: Design) -> str:
    """File name of the fitted profile, inside the output folder (the material is a profile
    name, checked when the design was read, so this is one plain file name)."""
    return f"{profile_name(d.net.material, 'design net.material')}-fitted.toml"


def _write(out: str | Path, files: dict[str, str], force: bool, inputs: list,
           meta: dict[str, Any] | None = None) -> list[str]:
    """Write `files` (text by name) as the whole output folder (`meta`: the manifest's
    provenance); their names, sorted."""
    with staged_dir(out, force=force, volatile=(TIMINGS,), inputs=inputs, meta=meta) as stage:
        for name, text in files.items():
            (stage / name).write_text(text)
    return sorted(files)


def band_summary(run: VerifyRun) -> list[str]:
    """One line per metric: the band verdict (for the command line's summary)."""
    from printgen.verification.compare import METRICS

    keep = run.band.levels
    proto = run.verification.prototype.deformation
    sel = [i for i, lv in enumerate(proto.levels) if any(abs(lv - k) < 1e-9 for k in keep)]
    curves = {k: proto.values[k][sel] for k in METRICS}
    return [f"{METRICS[b.metric]}: {b.text}" for b in band_verdicts(curves, run.band)]
