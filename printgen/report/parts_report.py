"""The report's sections of `make`'s steps: meshes, direct G-code, assembly and toolpath
previews, each from the record its step returned (printgen.run.steps), and the run's
provenance."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from printgen.outputs import MANIFEST
from printgen.report.html import Drawing, Report
from printgen.report.records import MeshRecord
from printgen.report.summary import print_rows

if TYPE_CHECKING:
    from printgen.parts.assembly import Assembly
    from printgen.report.records import GcodeRecord, PlateRecord


def meshes_section(rep: Report, parts: dict[str, MeshRecord | PlateRecord]) -> None:
    """The meshes' table: size on the bed, volume against the analytic one, triangles (a
    plate of several parts is not a mesh of its own)."""
    rows = []
    for name, rec in parts.items():
        if not isinstance(rec, MeshRecord):
            continue
        size = rec.size_mm
        rows.append([name, f"{size[0]:.1f} x {size[1]:.1f} x {size[2]:.2f}",
                     f"{rec.volume_mm3:.1f}", f"{rec.volume_error:+.2%}",
                     str(rec.triangles), f"{rec.bed_angle_deg:g}"])
    rep.heading("Meshes")
    rep.paragraph("One watertight body per part (STL, and a 3MF that opens in "
                  "PrusaSlicer with the part's settings), placed on the printer bed.")
    rep.table(["part", "size on bed (mm)", "volume mm^3", "vs analytic", "triangles",
               "turned (deg)"], rows)


def gcode_section(rep: Report, gcode: dict[str, GcodeRecord]) -> None:
    """The G-code's table: layers, volume, read-back errors, retractions (times go to
    timings.json: the report is reproducible)."""
    rows = [[name, r.file, str(r.layers), f"{r.volume_mm3:.1f}", f"{r.readback_error:+.2%}",
             "-" if r.readback_vs_stl is None else f"{r.readback_vs_stl:+.2%}",
             str(r.retractions)] for name, r in gcode.items()]
    rep.heading("Direct G-code")
    rep.paragraph("Every net strand is one straight extrusion through the crossings, the "
                  "strand families alternate per pass; the G-code is read back and its "
                  "extruded volume compared with the toolpath's.")
    rep.table(["part", "file", "layers", "volume (mm^3)", "read-back error",
               "read back vs STL", "retractions"], rows)
    rep.table(*print_rows(gcode))  # print time, filament and mass per part


def assembly_section(rep: Report, a: Assembly,
                     figures: Sequence[tuple[str, bytes | Drawing, str]]) -> None:
    """The kit's verdict, its labelled picture with the checks after printing, and the
    toolpath previews (`figures`: file name, PNG or its drawing, caption)."""
    rep.heading("Assembly")
    problems = a.problems()
    rep.verdict(not problems, "; ".join(problems) or
                "the kit closes: cables as long as the net's sides, every loop on its "
                "cable's line with the stated clearance")
    for name, png, caption in figures:
        if name == "preview-net.png":
            rep.heading("Toolpath previews")
        rep.figure(png, caption, name.removesuffix(".png"), also=name)
        if name == "assembly.png":
            rep.paragraph("Check after printing:")
            for k, line in enumerate(a.checklist(), 1):
                rep.paragraph(f"{k}. {line}")


def provenance_section(rep: Report, meta: dict[str, Any]) -> None:
    """The report's provenance: what made this folder (the manifest holds the same)."""
    rep.heading("Provenance")
    cmd = meta.get("command")
    rep.paragraph(f"printgen {meta['printgen_version']}; command: "
                  f"{' '.join(cmd) if cmd else 'printgen.make() from Python'}. Every file of "
                  f"this folder and its sha256 are in {MANIFEST}; `printgen check FOLDER` "
                  "verifies them.")
    rep.table(["input", "file", "sha256"],
              [[k, v["path"], v["sha256"]] for k, v in meta["inputs"].items()])
    env = meta["environment"]
    backend = env["solver_backend"] or {}
    rep.paragraph(f"Made with Python {env['python']}; solver backend (linear solves of the "
                  f"tangent): {', '.join(f'{k} {v}' for k, v in backend.items()) or 'none'}. "
                  "Other versions of these packages may change the last digits of the "
                  "results (the outputs are byte-identical for the same versions):")
    rep.table(["package", "version"], [[k, v or "not installed"]
                                       for k, v in env["packages"].items()])
