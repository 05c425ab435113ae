"""The steps of `printgen make`: plain functions `step(ctx, stage)` that add files under
`stage` and return their records (report.json key -> record, printgen.report.records); the
report is built once from them (printgen.report.build), their wall-clock times go to the
run's timings (`ctx.timings`). The pipeline is `printgen.run.make`. The verification's
sweeps (`verification_sweeps`) run in a helper process from the start of the run while the
other steps run here; the advice runs there too, beside the band's variants
(`sweeps_and_advice`). The report's figures are drawings (printgen.report.html.Drawing) until
the report is built; then they are drawn all at once, side by side in the helper's worker
processes (`draw_figures`).
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable
from concurrent.futures import Future
from concurrent.futures import TimeoutError as FutureTimeout
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from printgen.errors import TimeLimitError
from printgen.executor.local import seconds_left
from printgen.inputs.materials import load_material
from printgen.inputs.printers import load_print_style, load_printer
from printgen.trace import span

HELPER_SWEEPS = "helper: verification sweeps"  # timings_s keys of work done in the helper
WAIT_SWEEPS = "waiting for the verification sweeps"  # in this process, within a step
FIGURES = "figures (PNG and SVG, side by side)"  # within the report files, after the steps

if TYPE_CHECKING:  # pragma: no cover
    from printgen.inputs.printers import Printer
    from printgen.inputs.prototype import Prototype
    from printgen.parts.gcode.toolpath import Toolpath
    from printgen.report.html import Drawing
    from printgen.report.records import CheckRecords, MeshRecord, PlateRecord
    from printgen.run.make import MakeContext
    from printgen.run.options import RunOptions
    from printgen.scaling.record import Design
    from printgen.verification.advice import Advice
    from printgen.verification.bands import Band
    from printgen.verification.preprint import Verification


def preload_parts() -> None:
    """Import the mesh libraries now (the parts step needs them): trimesh's imports catch
    BaseException, so a signal must not arrive while they run (the caller holds signals)."""
    with contextlib.suppress(ImportError):  # the parts step says what is missing
        import trimesh  # noqa: F401


def part_toolpath(ctx: MakeContext, name: str, part: Any, printer: Printer) -> Toolpath:
    """The direct toolpath of part `name` ("net" or "cable-<name>"), built once per run:
    the G-code and the previews share it."""
    if name not in ctx.toolpaths:
        from printgen.parts.gcode import cable_toolpath, net_toolpath

        d = ctx.design
        mat, style = load_material(part.material), load_print_style(part.print_style)
        if name == "net":
            ctx.toolpaths[name] = net_toolpath(part, printer, style, mat,
                                               attachment=net_attachment(d, printer))
        else:
            ctx.toolpaths[name] = cable_toolpath(part, printer, style, mat)
    return ctx.toolpaths[name]


def gcode_step(ctx: MakeContext, stage: Path) -> dict[str, Any]:
    """Direct G-code for the net and each cable, checked by read-back against the design."""
    from printgen.parts.gcode.estimate import print_estimate
    from printgen.parts.gcode.readback import read_gcode_text
    from printgen.parts.gcode.writer import gcode_text
    from printgen.report.records import GcodeRecord

    d = ctx.design
    printer = load_printer(d.printer)
    parts = [("net", d.net)] + [(f"cable-{c.name}", c) for c in d.cables]
    rec, times = {}, ctx.timings.setdefault("gcode", {})
    for name, part in parts:
        mat = load_material(part.material)
        t0 = time.perf_counter()
        tp = part_toolpath(ctx, name, part, printer)
        est = print_estimate(tp, printer, mat)
        text = gcode_text(tp, printer, mat, title=f"{name}, 1:{d.scale:g}", estimate=est)
        back = read_gcode_text(text, filament_diameter_mm=printer.filament_diameter_mm)
        times[name] = {"seconds": time.perf_counter() - t0}
        path = stage / f"{name}.gcode"
        path.write_text(text)
        ctx.files.append(path.name)
        stl = ctx.volumes_mm3.get(name)
        vs_stl = back.volume_mm3 / stl - 1 if stl else None
        retractions = text.count(f"E-{mat.print.retract_length_mm:.5f}")
        rec[name] = GcodeRecord(path.name, len(back.layer_z_mm), tp.volume_mm3,
                                back.volume_mm3, vs_stl, retractions, est)
    out: dict[str, Any] = {"gcode": rec}
    if d.net.wave is not None:
        out["wave"] = wave_record(ctx, printer)
    return out


def wave_record(ctx: MakeContext, printer: Printer) -> Any:
    """The waved net's laws against the target and the straight net's, and its print time
    and mass against the straight net's (`WaveRecord`)."""
    from printgen.parts.gcode.price import wave_price
    from printgen.report.wave_report import WaveRecord
    from printgen.scene.waved import wave_laws

    d = ctx.design
    price = wave_price(d.net, printer, load_print_style(d.net.print_style),
                       load_material(d.net.material), attachment=net_attachment(d, printer))
    return WaveRecord(wave_laws(ctx.prototype, ctx.targets, d), price)


def net_attachment(d: Design, printer: Printer) -> Any:
    """The net's loops onto its border cables (None: a design without cables)."""
    from printgen.parts.geometry.attach import attachment_for

    return (attachment_for(d, hole_compensation_mm=printer.hole_compensation_mm)
            if d.cables else None)


def kit_step(ctx: MakeContext, stage: Path) -> dict[str, Any]:
    """How the kit goes together (labelled picture, checks after printing) and top views of
    the direct toolpaths per pass (the net's corner and a cable's eyelet)."""
    from printgen.parts.assembly import assemble
    from printgen.parts.geometry.solid import net_outline
    from printgen.report.kit import kit_figures
    from printgen.report.records import KitRecords

    d = ctx.design
    if not d.cables:
        return {}
    printer = load_printer(d.printer)
    a = assemble(d, printer)
    net_tp = part_toolpath(ctx, "net", d.net, printer)  # its attachment is a.attachment
    c = min(d.cables, key=lambda c: c.length_mm)
    cable_tp = part_toolpath(ctx, f"cable-{c.name}", c, printer)
    outline = net_outline(d.net, a.attachment)
    # drawn with the verification's figures, side by side, once the report is built (see
    # `draw_figures`); the pictures are also written beside the report (report_files)
    return {"assembly": KitRecords(a, kit_figures(a, outline, net_tp, cable_tp, c.name))}


def slicer_step(ctx: MakeContext, stage: Path) -> dict[str, Any]:
    """PrusaSlicer settings for every part (the whole config; its print and filament presets
    alone, for the lab's own printer; all presets as one config bundle) and, for the cables,
    CuraEngine settings, a Cura profile and its settings table."""
    from printgen.parts.slicer.cura import (
        cura_cfg_text,
        cura_settings,
        cura_table_csv,
        curaprofile_bytes,
    )
    from printgen.parts.slicer.prusa import (
        BUNDLE_FILE,
        design_presets,
        presets_ini_text,
        prusa_bundle_text,
    )

    d = ctx.design
    printer = load_printer(d.printer)
    presets = design_presets(d, printer)
    written = []
    for kind, name, part in [("net", "net", d.net)] + [("cable", f"cable-{c.name}", c)
                                                       for c in d.cables]:
        files = {f"{name}.prusa.ini": presets_ini_text(presets[name]),
                 f"{name}.prusa-print.ini": presets_ini_text(presets[name],
                                                             ("print", "filament"))}
        if kind == "cable":
            mat, style = load_material(part.material), load_print_style(part.print_style)
            files[f"{name}.cura.cfg"] = cura_cfg_text(kind, part, printer, style, mat)
            s = cura_settings(kind, part, printer, style, mat)
            files[f"{name}.cura-settings.csv"] = cura_table_csv(s)
            (stage / f"{name}.curaprofile").write_bytes(curaprofile_bytes(name, s))
            written.append(f"{name}.curaprofile")
        for file, text in files.items():
            (stage / file).write_text(text, encoding="utf-8")  # Cura's units hold a degree sign
        written += list(files)
    (stage / BUNDLE_FILE).write_text(prusa_bundle_text(list(presets.values())), encoding="utf-8")
    written.append(BUNDLE_FILE)
    ctx.files += written
    return {"slicer_profiles": sorted(written)}


def parts_step(ctx: MakeContext, stage: Path) -> dict[str, Any]:
    """Watertight meshes of every part: STL, a 3MF carrying its PrusaSlicer settings, and
    STEP when asked (--step, needs cadquery; the progress line names each part's STEP)."""
    from printgen.parts.slicer.prusa import design_presets, presets_ini_text

    d = ctx.design
    printer = load_printer(d.printer)
    parts = _mesh_parts(d, printer.hole_compensation_mm)
    presets = design_presets(d, printer)
    rec: dict[str, MeshRecord | PlateRecord] = {}
    cables = []
    for k, (name, kind, part, solid, outline, analytic) in enumerate(parts, 1):
        body = solid(part)
        if kind == "cable":
            cables.append((name, body))
        if ctx.options.step and ctx.progress:
            ctx.progress(f"STEP {name} ({k} of {len(parts)})")
        mesh = _write_part(stage, name, kind, part, body, printer,
                           outline if ctx.options.step else None, analytic(part),
                           presets_ini_text(presets[name]))
        rec[name] = mesh
        ctx.files += mesh.files
        ctx.volumes_mm3[name] = mesh.volume_mm3
    if cables:  # every cable on one plate: one print job, with the cables' settings
        ini = presets_ini_text(presets[f"cable-{d.cables[0].name}"])
        rec["cables-plate"] = _write_plate(stage, cables, printer, ini)
        ctx.files.append("cables-plate.3mf")
    return {"parts": rec}


def _mesh_parts(d: Design, comp: float) -> list[tuple]:
    """(file name, kind, part, solid, outline, analytic volume) of the net and each cable."""
    from printgen.parts.geometry.solid import (
        analytic_cable_volume,
        analytic_net_volume,
        attachment_for,
        cable_outline,
        cable_solid,
        net_outline,
        net_solid,
    )

    att = attachment_for(d, hole_compensation_mm=comp) if d.cables else None
    parts = [("net", "net", d.net, lambda p: net_solid(p, att), lambda p: net_outline(p, att),
              lambda p: analytic_net_volume(p, att))]
    parts += [(f"cable-{c.name}", "cable", c, lambda p: cable_solid(p, comp),
               lambda p: cable_outline(p, comp), lambda p: analytic_cable_volume(p, comp))
              for c in d.cables]
    return parts


def _write_part(stage: Path, name: str, kind: str, part, body, printer, outline,
                expected: float, ini: str | None = None) -> MeshRecord:
    """Place `body` on the bed and write its STL, 3MF carrying the PrusaSlicer settings `ini`
    (None: the part's own, its presets named after it alone) and STEP from `outline` when
    given; its record."""
    from printgen.parts.export import place_mesh, prusa_config_from_ini, stl_bytes, threemf_bytes
    from printgen.parts.slicer.prusa import prusa_ini_text
    from printgen.report.records import MeshRecord

    if ini is None:
        ini = prusa_ini_text(kind, part, printer, load_print_style(part.print_style),
                             load_material(part.material))
    mesh, angle = place_mesh(body, printer, name)
    (stage / f"{name}.stl").write_bytes(stl_bytes(mesh))
    (stage / f"{name}.3mf").write_bytes(threemf_bytes([(name, mesh)],
                                                       prusa_config_from_ini(ini)))
    files = [f"{name}.stl", f"{name}.3mf"]
    if outline is not None:
        from printgen.parts.geometry.cad import step_bytes

        (stage / f"{name}.step").write_bytes(step_bytes(outline(part),
                                                        part_thickness(kind, part)))
        files.append(f"{name}.step")
    size = mesh.bounds[1] - mesh.bounds[0]
    return MeshRecord(files, float(mesh.volume), expected, np.round(size, 4), len(mesh.faces),
                      bool(mesh.is_watertight), angle)


def _write_plate(stage: Path, cables: list[tuple[str, Any]], printer, ini: str
                 ) -> PlateRecord:
    """cables-plate.3mf: the cables laid out together on one bed; its record."""
    from printgen.parts.export import layout_parts, prusa_config_from_ini, threemf_bytes
    from printgen.report.records import PlateRecord

    placed = layout_parts(cables, printer)
    (stage / "cables-plate.3mf").write_bytes(threemf_bytes(
        [(p.name, p.mesh) for p in placed], prusa_config_from_ini(ini)))
    return PlateRecord(["cables-plate.3mf"], {p.name: p.angle_deg for p in placed})


def part_thickness(kind: str, part) -> float:
    return (part.strand if kind == "net" else part.section).thickness_mm


def verify_step(ctx: MakeContext, stage: Path) -> dict[str, Any]:
    """Prototype vs model over the loading sweep, the model's uncertainty band
    (printgen.verification.bands), and the steel counter-example, from the sweeps of the
    helper process `make` started them in, or computed here, with the advice (computed
    alongside the band's variants, `sweeps_and_advice`): their records
    (`verification_records`), their times in the run's timings."""
    done = sweeps_done(ctx)
    if done is None:
        done = sweeps_and_advice(ctx.prototype, ctx.design, ctx.options)
    v, band, early = done
    with span("verify: records"):
        check, times = verification_records(v, band, ctx.targets.scale)
    ctx.timings["verification"] = times
    advice = advice_for(ctx, v, band, early)
    return {"verification": check} | ({} if advice is None else {"advice": advice})


OUT_WORD = "OUT"  # how the advice's command names the run's output folder


def wants_advice(v: Verification) -> bool:
    """Whether the run advises a change: not on PASS, not when the flume cannot run the test
    (its fix, a capacity statement, needs no solve), and not when the nominal design already
    passes and only the band leaves the verdict UNDECIDED (a test settles it, not another
    net). On the nominal verification, before the band decides, it is wanted whenever the
    run's will be: the advice computed then is dropped should the band's verdict be PASS."""
    return v.verdict != "PASS" and v.runnable and not v.ok


def run_advice(prototype: Prototype, design: Design, options: RunOptions, v: Verification,
               coarsen: int) -> tuple[Advice, float]:
    """(what to change, printgen.verification.advice, and its wall time in s) for the run
    whose nominal verification is `v` and whose band runs on the net `coarsen` times
    coarser."""
    from printgen.verification.advice import advise, direction

    t, s = time.perf_counter(), v.sensors
    with span("advice"):
        a = advise(prototype, design, v.prototype,
                   sensors_too_strong=s is not None and s.too_strong,
                   sensor_limit_n=None if s is None else s.limit_n,
                   coarsen=coarsen, load=options.load, way=direction(v.mismatches),
                   start=v.model.states)
    return a, time.perf_counter() - t


def sweeps_and_advice(prototype: Prototype, design: Design, options: RunOptions
                      ) -> tuple[Verification, Band, tuple[Advice, float] | None]:
    """`verification_sweeps` with the advice (`run_advice`) computed while the band's
    variants run, its sweeps queued behind theirs on the same workers (None: no advice
    wanted by the nominal verification, `wants_advice`). The advice needs only the nominal
    verification and the band's coarsening, so it waits for no variant."""
    early: list[tuple[Advice, float]] = []

    def alongside(nominal: Verification, coarsen: int) -> None:
        if wants_advice(nominal):
            early.append(run_advice(prototype, design, options, nominal, coarsen))

    v, band = verification_sweeps(prototype, design, options, alongside=alongside)
    return v, band, early[0] if early else None


def advice_for(ctx: MakeContext, v: Verification, band: Band,
               early: tuple[Advice, float] | None) -> Advice | None:
    """What to change when the verdict is not PASS (`wants_advice`), from the advice computed
    alongside the band (`early`; computed here when missing), its "Next" line naming the
    run's files. Its wall time goes to the run's timings."""
    import dataclasses

    if not wants_advice(v):
        return None
    a, seconds = early if early is not None else run_advice(
        ctx.prototype, ctx.design, ctx.options, v, band.coarsen)
    ctx.timings.setdefault("timings_s", {})["advice"] = seconds
    # the folder as OUT, said so: the report does not depend on the folder's name or place
    # (the same inputs give the same files; a lab moves and archives the folder whole)
    out = None if ctx.out is None else OUT_WORD
    return dataclasses.replace(a, next=a.next_step(str(ctx.prototype.path),
                                                   ctx.targets.scale, out))


def sweeps_done(ctx: MakeContext
                ) -> tuple[Verification, Band, tuple[Advice, float] | None] | None:
    """The verification's sweeps and advice (`sweeps_and_advice`) when they ran in the
    helper process (waiting for them), else None."""
    pending = ctx.background.pop("verification sweeps", None)
    if pending is None:
        return None
    t = time.perf_counter()
    sweeps, seconds = _collect(pending, "the verification's sweeps")
    times = ctx.timings.setdefault("timings_s", {})
    times[HELPER_SWEEPS], times[WAIT_SWEEPS] = seconds, time.perf_counter() - t
    return sweeps


def draw_figures(ctx: MakeContext) -> None:
    """Draw the built report's figures not drawn yet (the kit's and the verification's), side by
    side in worker processes: those of the helper process when there is one (forked from a
    process running one thread, they start with matplotlib imported), else `Report.draw`'s.
    Their wall time goes to timings_s[FIGURES]."""
    if ctx.report is None:
        return
    t = time.perf_counter()
    todo = ctx.report.pending()
    with span("figures"):
        _draw(ctx, todo)
    if todo:
        ctx.timings.setdefault("timings_s", {})[FIGURES] = time.perf_counter() - t


def _draw(ctx: MakeContext, todo: list[Drawing]) -> None:
    assert ctx.report is not None
    if todo and ctx.helper is not None:
        pngs, _ = _collect(ctx.helper.submit(timed, draw_all, todo), "the report's figures")
        ctx.report.fill(pngs)
    else:
        ctx.report.draw()


def draw_all(drawings: list[Drawing]) -> list[bytes]:
    """Each drawing's PNG (carrying its SVG), side by side in worker processes when there are
    several and two cores (printgen.executor.local.run_jobs); matplotlib is imported here first, so
    that forked workers start with it."""
    from printgen.report.html import drawn
    from printgen.report.plots import load_pyplot

    load_pyplot()
    return drawn(drawings)


def _collect(pending: Future, what: str) -> Any:
    """A helper job's result, waiting no longer than the run's deadline
    (`printgen.executor.local.deadline`): past it, TimeLimitError naming `what` (the helper is then
    stopped)."""
    left = seconds_left()
    try:
        return pending.result(timeout=None if left is None else max(left, 0.0))
    except FutureTimeout as exc:
        raise TimeLimitError(f"{what}: past the time limit") from exc


def timed(fn: Callable, /, *args: Any, **kwargs: Any) -> tuple[Any, float]:
    """(fn(*args, **kwargs), its wall time in s): a helper job and how long it took there."""
    t = time.perf_counter()
    return fn(*args, **kwargs), time.perf_counter() - t


def verification_sweeps(prototype: Prototype, design: Design, options: RunOptions, *,
                        alongside: Callable[[Verification, int], object] | None = None
                        ) -> tuple[Verification, Band]:
    """Both barriers' load sweeps compared, and the model's uncertainty band, under the
    run's load case (`options.load`; each of `options.loads` too, nominal sweeps only).

    The sweep is the scene realistic-1:40 with border cables, simple-free-top without them
    (docs/physics.md: Pre-print verification); every load level is solved on both. Needs nothing
    from the other steps, so it can run in a worker process while they run. `alongside`: as
    `verify_with_band`'s.
    """
    from printgen.report.plots import load_pyplot
    from printgen.verification.pooled import verify_with_band
    from printgen.verification.preprint import free_section

    # matplotlib is imported while the sweeps run: the figures' workers start with it
    return verify_with_band(prototype, design, load=options.load, counterexample=True,
                            free_section=free_section(prototype), meanwhile=load_pyplot,
                            loads=tuple(options.loads), alongside=alongside)


def solver_work(v: Verification, band: Band) -> dict[str, Any]:
    """What the solver did over the whole verification (`printgen.run.budget.counted_work`):
    the nominal sweeps of every load case (and of the prototype with the sensors scaled), the
    band's refinement test and variants, and the prototype's band."""
    from printgen.run.budget import counted_work

    cases = [c for c in v.by_load.values() if c.spec != v.load.get("spec")]  # not v's own
    nominal = [r for c in [v, *cases] for r in (c.model, c.prototype)]
    if v.loaded_prototype is not None:  # the prototype with the sensors scaled (sensors.py)
        nominal.append(v.loaded_prototype)
    theirs = v.prototype_band.work if v.prototype_band is not None else []
    return counted_work([*(r.work() for r in nominal), *band.work, *theirs])


def verification_records(v: Verification, band: Band, scale: float
                         ) -> tuple[CheckRecords, dict[str, Any]]:
    """The verification's records (with the solver's work, the lab's curves and expected
    readings: printgen.report.records.CheckRecords) and their wall-clock times, at the paths
    timings.json holds them ("bands", "solver_work")."""
    from printgen.report.records import CheckRecords
    from printgen.run.provenance import split_timings

    work, work_times = split_timings(solver_work(v, band))
    times: dict[str, Any] = {"bands": {"seconds": band.seconds}}
    if work_times:
        times["solver_work"] = work_times
    return CheckRecords(v, band, scale, solver_work=work, counterexample=True), times
