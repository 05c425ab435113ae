"""The report of a run, built once from its records (printgen.report.records) for `make` and
`verify` alike (verify's run has fewer records): report.html's sections in the flow's order
under the summary box, and the files beside the report (each figure as PNG and SVG under
figures/, the kit's pictures, the lab's CSV files). report.json is the records' own
(`RunRecords.to_record`) with the summary's."""

from __future__ import annotations

from printgen.report.flume_drawing import layout_section
from printgen.report.html import Report
from printgen.report.jsonout import dumps
from printgen.report.labfiles import lab_files
from printgen.report.parts_report import (
    assembly_section,
    gcode_section,
    meshes_section,
    provenance_section,
)
from printgen.report.records import CheckRecords, KitRecords, RunRecords
from printgen.report.report import design_sections, load_case_sections, verification_sections
from printgen.report.summary import Summary, summarize, summary_html
from printgen.report.uncertainty import band_sections, measured_sections
from printgen.report.wave_report import wave_section
from printgen.verification.advice import NEXT_DESIGN

FIGURES = "figures"  # folder of the figure files in the output


def build_report(run: RunRecords) -> tuple[Report, Summary]:
    """report.html's content from the run's records, its figures not drawn yet (drawings:
    `Report.draw`, or a helper's workers), and the run's summary (the box on top)."""
    rep = Report(run.title)
    if run.plan is not None:
        p = run.plan
        design_sections(rep, p.prototype, p.targets, p.selection, p.design,
                        design_file=p.design_file, own_net=p.own_net)
    if "parts" in run.steps:
        meshes_section(rep, run.steps["parts"])
    if "gcode" in run.steps:
        gcode_section(rep, run.steps["gcode"])
    if "wave" in run.steps:
        wave_section(rep, run.steps["wave"])
    kit = run.steps.get("assembly")
    if isinstance(kit, KitRecords):
        assembly_section(rep, kit.assembly, kit.figures)
    if run.check is not None:
        check_sections(rep, run.check)
    m = run.measured
    if m is not None and run.check is not None:
        measured_sections(rep, m.measurement, m.band, m.fit, m.profile,
                          prototype=run.check.verification.prototype.deformation)
    if run.provenance is not None:
        provenance_section(rep, run.provenance)
    summary = summarize(run, m.sentence() if m is not None else "")
    rep.lead = summary_html(summary)
    return rep, summary


def check_sections(rep: Report, check: CheckRecords) -> None:
    """The pre-print verification, its band, the load cases' readings and the flume layout."""
    from printgen.scene.flume import flume_layout

    v = check.verification
    verification_sections(rep, v, v.counterexample if check.counterexample else None,
                          check.scale, band=check.band)
    band_sections(rep, v, check.band)
    load_case_sections(rep, v)
    layout_section(rep, flume_layout(v.model.scene))


def report_files(run: RunRecords, rep: Report, *, figures: bool = True) -> dict[str, bytes]:
    """The files beside the report by relative path: with `figures`, each figure (drawn now
    when not drawn yet: `Report.draw`) numbered in report order as figures/NN-name.png and
    .svg (and the kit's pictures beside the report); the lab's CSV files."""
    out: dict[str, bytes] = {}
    if figures:
        rep.draw()
        for k, f in enumerate(rep.figures, 1):
            stem = f"{FIGURES}/{k:02d}-{f.name}"
            out[f"{stem}.png"], out[f"{stem}.svg"] = f.png, f.svg
            if f.also:
                out[f.also] = f.png
    if run.check is not None:
        out.update({name: text.encode("utf-8") for name, text in lab_files(run.check.lab).items()})
    advice = run.steps.get("advice")
    if advice is not None and advice.design is not None:  # the verified net, for make --design
        out[NEXT_DESIGN] = dumps(advice.design.to_dict()).encode("utf-8")
    return out
