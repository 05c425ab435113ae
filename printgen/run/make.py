"""`printgen make`: prototype + lambda -> targets, selection, design, printable parts, slicer
profiles, direct G-code, verification, report; every file staged and moved into the output
directory only when every step succeeded (a failed run leaves the previous outputs intact).

Steps are plain functions `step(ctx, stage)` run in order; each adds files under `stage` and
numbers to `ctx.record`.
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from printgen.design.design_file import load_design
from printgen.design.plan import make_design
from printgen.design.record import Design
from printgen.design.selection import Selection, select
from printgen.design.similitude import ScaledTargets, scale_targets
from printgen.inputs.materials import load_material
from printgen.inputs.printers import load_print_style, load_printer
from printgen.inputs.prototype import Prototype, load_prototype
from printgen.outputs import MANIFEST, check_destination, staged_dir
from printgen.report.html import Report
from printgen.report.jsonout import dumps
from printgen.report.report import design_record, design_sections
from printgen.run.budget import DEFAULT_LIMIT_S, Estimate, check_budget, level_bars
from printgen.run.provenance import (  # noqa: F401 (json_output, TIME_KEYS: used via make)
    TIME_KEYS,
    TIMINGS,
    json_output,
    provenance,
    provenance_section,
    split_timings,
)

log = logging.getLogger(__name__)


@dataclass
class MakeContext:
    """What the steps share: inputs, the chosen design, the report being built."""

    prototype: Prototype
    targets: ScaledTargets
    selection: Selection
    design: Design
    report: Report
    options: dict[str, Any]
    record: dict[str, Any] = field(default_factory=dict)
    files: list[str] = field(default_factory=list)


Step = Callable[[MakeContext, Path], None]


def plan(prototype_path: str | Path, scale: float, *, printer: str | None = None,
         options: dict[str, Any] | None = None) -> MakeContext:
    """Targets, selection and design: the fast, file-free part of `make`."""
    proto = load_prototype(prototype_path)
    t = scale_targets(proto, scale)
    sel = select(proto, t, printer=printer)
    design = make_design(proto, t, sel)
    design_file = (options or {}).get("design_file")
    if design_file:  # the net of `printgen design` (its design.json) instead of select's
        design = load_design(design_file, scale=t.scale)
    rep = Report(f"printgen: {proto.name} at 1:{t.scale:g}")
    design_sections(rep, proto, t, sel, design)
    ctx = MakeContext(proto, t, sel, design, rep, options or {})
    ctx.record.update(design_record(proto, t, sel, design))
    if design_file:
        ctx.record["design_file"] = Path(design_file).name
        rep.paragraph(f"The printed parts are the design of {Path(design_file).name} "
                      "(printgen design), not the selection's choice above.")
    return ctx


def gcode_step(ctx: MakeContext, stage: Path) -> None:
    """Direct G-code for the net and each cable, checked by read-back against the design."""
    from printgen.parts.gcode import cable_toolpath, net_toolpath
    from printgen.parts.gcode.readback import read_gcode_text
    from printgen.parts.gcode.writer import gcode_text
    from printgen.parts.geometry.attach import attachment_for

    d = ctx.design
    printer = load_printer(d.printer)
    att = (attachment_for(d, hole_compensation_mm=printer.hole_compensation_mm)
           if d.cables else None)

    def net_path(*args):
        return net_toolpath(*args, attachment=att)

    parts = [("net", d.net, net_path)] + [(f"cable-{c.name}", c, cable_toolpath)
                                          for c in d.cables]
    rows, rec = [], {}
    for name, part, build in parts:
        mat, style = load_material(part.material), load_print_style(part.print_style)
        t0 = time.perf_counter()
        tp = build(part, printer, style, mat)
        text = gcode_text(tp, printer, mat, title=f"{name}, 1:{d.scale:g}")
        back = read_gcode_text(text, filament_diameter_mm=printer.filament_diameter_mm)
        seconds = time.perf_counter() - t0
        path = stage / f"{name}.gcode"
        path.write_text(text)
        ctx.files.append(path.name)
        err = back.volume_mm3 / tp.volume_mm3 - 1
        stl = ctx.record.get("parts", {}).get(name, {}).get("volume_mm3")
        vs_stl = back.volume_mm3 / stl - 1 if stl else None
        retractions = text.count(f"E-{mat.print.retract_length_mm:.5f}")
        rec[name] = {"file": path.name, "layers": len(back.layer_z_mm),
                     "volume_mm3": tp.volume_mm3, "readback_volume_mm3": back.volume_mm3,
                     "readback_error": err, "readback_vs_stl": vs_stl,
                     "retractions": retractions, "seconds": seconds}
        rows.append([name, path.name, str(len(back.layer_z_mm)), f"{tp.volume_mm3:.1f}",
                     f"{err:+.2%}", "-" if vs_stl is None else f"{vs_stl:+.2%}",
                     str(retractions)])  # times go to timings.json: the report is reproducible
    ctx.record["gcode"] = rec
    ctx.report.heading("Direct G-code")
    ctx.report.paragraph("Every net strand is one straight extrusion through the crossings, the "
                         "strand families alternate per pass; the G-code is read back and its "
                         "extruded volume compared with the toolpath's.")
    ctx.report.table(["part", "file", "layers", "volume mm^3", "read-back error",
                      "read back vs STL", "retractions"], rows)


def kit_step(ctx: MakeContext, stage: Path) -> None:
    """How the kit goes together (labelled picture, checks after printing) and top views of
    the direct toolpaths per pass (the net's corner and a cable's eyelet)."""
    from printgen.parts.assembly import assemble
    from printgen.parts.gcode import cable_toolpath, net_toolpath
    from printgen.parts.geometry.solid import net_outline
    from printgen.report.kit import kit_figures

    d = ctx.design
    if not d.cables:
        return
    printer = load_printer(d.printer)
    a = assemble(d, printer)
    net_tp = net_toolpath(d.net, printer, load_print_style(d.net.print_style),
                          load_material(d.net.material), attachment=a.attachment)
    c = min(d.cables, key=lambda c: c.length_mm)
    cable_tp = cable_toolpath(c, printer, load_print_style(c.print_style),
                              load_material(c.material))
    figs = kit_figures(a, net_outline(d.net, a.attachment), net_tp, cable_tp, c.name)
    ctx.report.heading("Assembly")
    problems = a.problems()
    ctx.report.verdict(not problems, "; ".join(problems) or
                       "the kit closes: cables as long as the net's sides, every loop on its "
                       "cable's line with the stated clearance")
    for name, png, caption in figs:
        (stage / name).write_bytes(png)
        ctx.files.append(name)
        if name == "preview-net.png":
            ctx.report.heading("Toolpath previews")
        ctx.report.figure(png, caption)
        if name == "assembly.png":
            ctx.report.paragraph("Check after printing:")
            for k, line in enumerate(a.checklist(), 1):
                ctx.report.paragraph(f"{k}. {line}")
    ctx.record["assembly"] = a.to_record()


def slicer_step(ctx: MakeContext, stage: Path) -> None:
    """PrusaSlicer .ini for every part and CuraEngine settings for the cables."""
    from printgen.parts.slicer.cura import cura_cfg_text
    from printgen.parts.slicer.prusa import prusa_ini_text

    d = ctx.design
    printer = load_printer(d.printer)
    written = []
    for kind, name, part in [("net", "net", d.net)] + [("cable", f"cable-{c.name}", c)
                                                       for c in d.cables]:
        mat, style = load_material(part.material), load_print_style(part.print_style)
        ini = stage / f"{name}.prusa.ini"
        ini.write_text(prusa_ini_text(kind, part, printer, style, mat))
        written.append(ini.name)
        if kind == "cable":
            cfg = stage / f"{name}.cura.cfg"
            cfg.write_text(cura_cfg_text(kind, part, printer, style, mat))
            written.append(cfg.name)
    ctx.files += written
    ctx.record["slicer_profiles"] = written


def parts_step(ctx: MakeContext, stage: Path) -> None:
    """Watertight meshes of every part: STL, a 3MF carrying its PrusaSlicer settings, and
    STEP when asked (--step, needs cadquery)."""
    from printgen.parts.export import (
        layout_parts,
        place_mesh,
        prusa_config_from_ini,
        stl_bytes,
        threemf_bytes,
    )
    from printgen.parts.geometry.solid import (
        analytic_cable_volume,
        analytic_net_volume,
        attachment_for,
        cable_outline,
        cable_solid,
        net_outline,
        net_solid,
    )
    from printgen.parts.slicer.prusa import prusa_ini_text

    d = ctx.design
    printer = load_printer(d.printer)
    comp = printer.hole_compensation_mm
    att = attachment_for(d, hole_compensation_mm=comp) if d.cables else None
    parts = [("net", "net", d.net, lambda p: net_solid(p, att), lambda p: net_outline(p, att),
              lambda p: analytic_net_volume(p, att))]
    parts += [(f"cable-{c.name}", "cable", c, lambda p: cable_solid(p, comp),
               lambda p: cable_outline(p, comp), lambda p: analytic_cable_volume(p, comp))
              for c in d.cables]
    rows, rec = [], {}
    for name, kind, part, solid, outline, analytic in parts:
        mat, style = load_material(part.material), load_print_style(part.print_style)
        mesh, angle = place_mesh(solid(part), printer, name)
        ini = prusa_ini_text(kind, part, printer, style, mat)
        (stage / f"{name}.stl").write_bytes(stl_bytes(mesh))
        (stage / f"{name}.3mf").write_bytes(threemf_bytes([(name, mesh)],
                                                           prusa_config_from_ini(ini)))
        files = [f"{name}.stl", f"{name}.3mf"]
        if ctx.options.get("step"):
            from printgen.parts.geometry.cad import step_bytes

            (stage / f"{name}.step").write_bytes(step_bytes(outline(part),
                                                            part_thickness(kind, part)))
            files.append(f"{name}.step")
        ctx.files += files
        expected = analytic(part)
        size = mesh.bounds[1] - mesh.bounds[0]
        rec[name] = {"files": files, "volume_mm3": float(mesh.volume),
                     "analytic_volume_mm3": expected,
                     "volume_error": float(mesh.volume) / expected - 1,
                     "size_mm": np.round(size, 4), "triangles": len(mesh.faces),
                     "watertight": bool(mesh.is_watertight), "bed_angle_deg": angle}
        rows.append([name, f"{size[0]:.1f} x {size[1]:.1f} x {size[2]:.2f}",
                     f"{mesh.volume:.1f}", f"{float(mesh.volume) / expected - 1:+.2%}",
                     str(len(mesh.faces)), f"{angle:g}"])
    if d.cables:  # every cable on one plate: one print job, with the cables' settings
        c = d.cables[0]
        ini = prusa_ini_text("cable", c, printer, load_print_style(c.print_style),
                             load_material(c.material))
        placed = layout_parts([(f"cable-{c.name}", cable_solid(c, comp)) for c in d.cables],
                              printer)
        (stage / "cables-plate.3mf").write_bytes(threemf_bytes(
            [(p.name, p.mesh) for p in placed], prusa_config_from_ini(ini)))
        ctx.files.append("cables-plate.3mf")
        rec["cables-plate"] = {"files": ["cables-plate.3mf"],
                               "parts": {p.name: p.angle_deg for p in placed}}
    ctx.record["parts"] = rec
    ctx.report.heading("Meshes")
    ctx.report.paragraph("One watertight body per part (STL, and a 3MF that opens in "
                         "PrusaSlicer with the part's settings), placed on the printer bed.")
    ctx.report.table(["part", "size on bed (mm)", "volume mm^3", "vs analytic", "triangles",
                      "turned (deg)"], rows)


def part_thickness(kind: str, part) -> float:
    return (part.strand if kind == "net" else part.section).thickness_mm


def verify_step(ctx: MakeContext, stage: Path) -> None:
    """Prototype vs model over the loading sweep, the model's uncertainty band
    (printgen.check.bands), and the steel counter-example.

    The sweep is the scene realistic-1:40 with border cables, simple-free-top without them
    (barrier-physics.md, section 7); every load level is solved on both.
    """
    from printgen.check.bands import model_band, model_load_kw
    from printgen.check.verify import verify
    from printgen.report.report import verification_record, verification_sections
    from printgen.report.uncertainty import band_record, band_sections

    drag = bool(ctx.options.get("drag"))
    v = verify(ctx.prototype, ctx.design, drag=drag, counterexample=True)
    band = model_band(ctx.design, v.model, load_kw=model_load_kw(ctx.prototype, ctx.design, drag))
    verification_sections(ctx.report, v, v.counterexample, ctx.targets.scale, band=band)
    band_sections(ctx.report, v, band)
    ctx.record["verification"] = verification_record(v, v.counterexample)
    ctx.record["verification"]["bands"] = band_record(v, band)


LONG_RUN_S = 30.0  # runs estimated longer than this show their estimate and progress


def make(prototype_path: str | Path, scale: float, out: str | Path, *,
         printer: str | None = None, steps: list[tuple[str, Step]] | None = None,
         options: dict[str, Any] | None = None,
         progress: Callable[[str], None] | None = None) -> MakeContext:
    """Run every step into a stage folder and swap it in as the whole of `out`.

    options: "force" (replace a folder printgen did not write), "command" (the command line,
    recorded in the manifest), "drag", "step". `out` gets manifest.json (files, inputs,
    version, command line) and timings.json (the only file that differs between runs).
    """
    t0 = time.perf_counter()
    check_destination(Path(out), force=bool((options or {}).get("force")))  # fail fast
    ctx = plan(prototype_path, scale, printer=printer, options=options)
    est = size_check(ctx, steps is None or any(s is verify_step for _, s in steps))
    if progress and est.seconds > LONG_RUN_S:
        progress(f"estimate: {est.summary()}")
    meta: dict[str, Any] = {}
    long_run = progress if est.seconds > LONG_RUN_S else None  # per-level bars when long
    with staged_dir(out, force=bool(ctx.options.get("force")), meta=meta,
                    volatile=(TIMINGS,)) as stage, level_bars(long_run):
        for label, step in steps if steps is not None else default_steps():
            if progress:
                progress(label)
            t = time.perf_counter()
            step(ctx, stage)
            ctx.record.setdefault("timings_s", {})[label] = time.perf_counter() - t
        meta.update(provenance(ctx))
        provenance_section(ctx.report, meta)
        ctx.record["files"] = sorted([*ctx.files, "report.html", "report.json", "design.json",
                                      MANIFEST, TIMINGS])
        ctx.record.setdefault("timings_s", {})["total"] = time.perf_counter() - t0
        stable, timings = split_timings(ctx.record)
        (stage / "design.json").write_text(dumps(ctx.design.to_dict()))
        (stage / "report.json").write_text(dumps(stable))
        (stage / "report.html").write_text(ctx.report.html())
        (stage / TIMINGS).write_text(dumps(timings))
    log.info("make finished in %.2f s", time.perf_counter() - t0)
    return ctx


def size_check(ctx: MakeContext, verifies: bool) -> Estimate:
    """Estimate the run before any of it is done; InputError when it is over the limit
    (options["time_limit_s"], default about a minute on 2 cores)."""
    cores = 1 if os.environ.get("PRINTGEN_SERIAL") else min(2, os.cpu_count() or 1)
    limit = ctx.options.get("time_limit_s") or DEFAULT_LIMIT_S
    est = check_budget(ctx.prototype, ctx.design, limit_s=float(limit), cores=cores,
                       sweep=verifies)
    ctx.record["size"] = est.to_record()
    ctx.record.setdefault("timings_s", {})["estimate"] = est.seconds
    return est


def default_steps() -> list[tuple[str, Step]]:
    return [("meshes (STL, 3MF)", parts_step), ("slicer profiles", slicer_step),
            ("direct G-code", gcode_step), ("assembly and toolpath previews", kit_step),
            ("verification (prototype and model load sweeps)", verify_step)]
