"""The `printgen make` report: targets, selection, parts and the pre-print verification, as
HTML (with embedded plots) and as one JSON record of every number."""

from __future__ import annotations

from typing import Any

from printgen.design import Design
from printgen.htmlreport import Report
from printgen.prototype import Prototype
from printgen.selection import Candidate, Selection, selection_record
from printgen.similitude import ScaledTargets, targets_record

SHOW = 6  # candidates per component in the report's tables (all are in report.json)


def design_sections(rep: Report, proto: Prototype, t: ScaledTargets, sel: Selection,
                    design: Design) -> None:
    """Targets, flow checks, the ranked selection and the chosen design."""
    rep.paragraph(f"Prototype: {proto.name} ({proto.description}). Model scale 1:{t.scale:g}. "
                  "Similitude of Lambert et al. (2023), J. Hydraul. Eng. 149(3), "
                  "doi:10.1061/JHEND8.HYENG-13070: Froude scaling with stiffness scaled too.")
    rep.heading("Similitude targets")
    rep.table(["quantity", "unit", "exponent", "prototype", "model"],
              [[r.label, r.unit, f"{r.exponent:g}", f"{r.prototype:.4g}", f"{r.model:.4g}"]
               for r in t.rows])
    f = t.flow
    rep.paragraph(f"Model flow: v = {f.velocity:.3g} m/s, depth {f.depth * 1e3:.3g} mm, Froude "
                  f"{f.froude:.2f}, Reynolds {f.reynolds:.0f} (hydraulic radius "
                  f"{f.hydraulic_radius * 1e3:.3g} mm; turbulent above 2500), discharge "
                  f"{f.discharge * 1e3:.3g} L/s.")
    for w in f.warnings:
        rep.verdict(False, w)
    for what, cands, why in (("Border cables", sel.cables, sel.cable_rationale),
                             ("Net", sel.net, sel.net_rationale)):
        if not cands:
            continue
        rep.heading(f"Selection: {what.lower()}")
        rep.paragraph(why)
        rep.table(["#", "material", "E source", "section (mm)", "passes", "stiffness",
                   "target", "error", "Pi3", "safety factor"],
                  [_row(i + 1, c) for i, c in enumerate(cands[:SHOW])])
    rep.heading("Printed parts")
    n = design.net
    rows = [["net", n.material.upper(), f"{n.width_mm:g} x {n.height_mm:g}",
             f"mesh {n.mesh_x_mm:g} x {n.mesh_y_mm:g}, strand {n.strand.width_mm:g} x "
             f"{n.strand.thickness_mm:g} mm, {n.strand.passes} passes"]]
    rows += [[f"cable {c.name}", c.material.upper(), f"{c.length_mm:g} long",
              f"{c.section.width_mm:g} x {c.section.thickness_mm:g} mm, {c.section.passes} "
              f"passes, eyelets {c.eyelet_inner_mm:g}/{c.eyelet_outer_mm:g} mm"]
             for c in design.cables]
    rep.table(["part", "material", "size (mm)", "section"], rows)


def _row(rank: int, c: Candidate) -> list[str]:
    s = c.section
    return [str(rank), c.material_name, c.modulus_source, f"{s.width_mm:g} x {s.thickness_mm:g}",
            str(s.passes), f"{c.stiffness:.4g}", f"{c.target:.4g}", f"{c.error:+.1%}",
            f"{c.pi3_deviation:+.0%}", f"{c.safety_factor:.1f}"]


def design_record(proto: Prototype, t: ScaledTargets, sel: Selection,
                  design: Design) -> dict[str, Any]:
    """The JSON part of the report for targets, selection and design."""
    return {"targets": targets_record(t, proto.name), "selection": selection_record(sel),
            "design": design.to_dict()}
