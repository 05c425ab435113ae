"""The report's sections of the plan (targets, selection, the printed parts) and of the
pre-print verification, rendered from their objects (printgen.report.build puts them in
order; report.json is the same objects' records)."""

from __future__ import annotations

import numpy as np

from printgen.barrier.patterns import mesh_text
from printgen.inputs.prototype import Prototype
from printgen.report.html import Drawing, Report
from printgen.scaling.record import Design
from printgen.scaling.selection import Candidate, Selection
from printgen.scaling.similitude import FORCE_EXPONENT, ScaledTargets, to_prototype
from printgen.verification.bands import Band
from printgen.verification.preprint import SHAPE_LEVELS, CounterExample, Verification

SHOW = 6  # candidates per component in the report's tables (all are in report.json)
SHOWN_LEVEL = 1.0  # relative loading of the 3D picture of both deformed nets


def design_sections(rep: Report, proto: Prototype, t: ScaledTargets, sel: Selection,
                    design: Design, *, design_file: str | None = None,
                    own_net: Candidate | None = None) -> None:
    """Targets, flow checks, the ranked selection and the chosen design (that of
    `design_file`, printgen design's, when given, with `own_net`: its net scored like the
    selection's candidates)."""
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
    for w in t.warnings:
        rep.verdict(False, w)
    for what, cands, why in (("Border cables", sel.cables, sel.cable_rationale),
                             ("Net", sel.net, sel.net_rationale)):
        if not cands:
            continue
        rep.heading(f"Selection: {what.lower()}")
        rep.paragraph(why)
        unit = "E*A, N" if what == "Border cables" else "initial membrane across / up, N/m"
        rep.table(["#", "material", "E source", "section (mm)", "passes", f"stiffness ({unit})",
                   f"target ({unit})", "stiffness error", "Pi3 deviation", "safety factor (-)"],
                  [_row(i + 1, c) for i, c in enumerate(cands[:SHOW])])
        same = _same_stiffness(cands[:SHOW])
        if same:
            rep.paragraph(f"Equivalent rows (#{same.replace('; ', ' and #')}): the same material "
                          "and bead area laid out differently (beads across x layers), so the "
                          "same stiffness; the ranking between them is the shape's.", "note")
    rep.heading("Printed parts")
    n = design.net
    rows = [["net", n.material.upper(), f"{n.width_mm:g} x {n.height_mm:g}",
             (f"{mesh_text(n.pattern, n.mesh_x_mm, n.mesh_y_mm)}, strand "
              f"{n.strand.width_mm:g} x {n.strand.thickness_mm:g} mm, {n.strand.passes} passes")]]
    rows += [[f"cable {c.name}", c.material.upper(), f"{c.length_mm:g} long",
              (f"{c.section.width_mm:g} x {c.section.thickness_mm:g} mm, {c.section.passes} "
              f"passes, eyelets {c.eyelet_inner_mm:g}/{c.eyelet_outer_mm:g} mm")]
             for c in design.cables]
    rep.table(["part", "material", "size (mm)", "section"], rows)
    if design_file:
        own = "" if own_net is None else (
            f" Its net's initial membrane stiffness: {own_net.stiffness_across:.4g} N/m across "
            f"the barrier against the target {own_net.target_across:.4g} N/m "
            f"({own_net.error_across:+.0%}), {own_net.stiffness_up:.4g} N/m up it against "
            f"{own_net.target_up:.4g} N/m ({own_net.error_up:+.0%}), safety factor "
            f"{own_net.safety_factor:.2f}.")
        rep.paragraph(f"The printed parts are the design of {design_file} "
                      f"(printgen design), not the selection's choice above.{own}")


def _same_stiffness(cands: tuple[Candidate, ...] | list[Candidate]) -> str:
    """'1-3, 4-5': runs of ranked rows with the same material and section area."""
    groups, out = {}, []
    for i, c in enumerate(cands, 1):
        groups.setdefault((c.material, round(c.section.area_mm2, 9)), []).append(i)
    for rows in groups.values():
        if len(rows) > 1:
            out.append(", ".join(map(str, rows)))
    return "; ".join(out)


def _row(rank: int, c: Candidate) -> list[str]:
    s = c.section
    return [str(rank), c.material_name, c.modulus_source, f"{s.width_mm:g} x {s.thickness_mm:g}",
            str(s.passes), *_stiffness_cells(c),
            f"{c.pi3_deviation:+.0%}", f"{c.safety_factor:.1f}"]


def _stiffness_cells(c: Candidate) -> list[str]:
    """Stiffness, target and error cells: across / up for a net (never one number), E*A for a
    cable."""
    if c.stiffness_across is None:
        return [f"{c.stiffness:.4g}", f"{c.target:.4g}", f"{c.error:+.1%}"]
    return [f"{c.stiffness_across:.4g} / {c.stiffness_up:.4g}",
            f"{c.target_across:.4g} / {c.target_up:.4g}",
            f"{c.error_across:+.1%} / {c.error_up:+.1%}"]


def verification_sections(rep: Report, v: Verification | None, ce: CounterExample | None,
                          scale: float, note: str = "", band: Band | None = None) -> None:
    """The pre-print check: verdict, side-by-side table, figure (with the model's uncertainty
    band when given), counter-example."""
    rep.heading("Pre-print verification: prototype vs printed model")
    if v is None:
        rep.verdict(False, f"Verification {note}")
    else:
        _sweep_sections(rep, v, scale, band)
    if ce is not None:
        _counterexample_section(rep, ce)


def _sweep_sections(rep: Report, v: Verification, scale: float, band: Band | None = None
                    ) -> None:
    from printgen.report.plots import verification_figure
    from printgen.verification.compare import METRICS, TOLERANCE, headlines

    rep.paragraph(
        f"Both barriers are solved as tension-only cable nets (printgen.solver) under the same "
        "relative "
        f"loading, {v.load_case}, h / h_B = 0 to 1.1 in steps of 0.05 (the reference's loading "
        "test: water raised behind a folded film), mounted alike and read by the same three "
        "sensor wires (bottom cable, top cable, mid-height); the model's wires pull 1 N along "
        "themselves. Deformations are normalised by each barrier's own width and height; "
        "tensions of the model are multiplied by lambda^3. The assumptions of each scene:")
    _assumption_tables(rep, v)
    if v.flow is not None and v.flow.limits:  # the verdict's too: not a pass
        for lim in v.flow.limits:
            rep.verdict(False, f"the flume cannot run this test: {lim.text}")
        rep.paragraph(f"What clears it: {v.flow.fix}. Assumed: the scaled flow fills the "
                      "flume's width w, so Q = v h w scales as lambda^-1.5 in this flume and the "
                      "model is w_B / lambda wide; the Froude number is the same at every scale. "
                      "The hydrostatic test behind the film needs no discharge, but the flowing "
                      "test the flume is for does, so the verdict counts it.")
    for line in headlines(v.mismatches):  # one per direction of error
        rep.verdict(v.ok, line)
    rep.paragraph(f"Tolerance: {TOLERANCE:.0%} of the prototype's peak, over the whole loading "
                  "range.", "note")
    for reason in v.reasons:
        rep.paragraph(reason)
    for who, run in (("prototype", v.prototype), ("model", v.model)):
        for level, why in run.failed.items():
            rep.verdict(False, f"{who}: no converged state at h/h_B = {level:g}, left out of the "
                               f"comparison: {why}")
    if not v.complete:
        rep.paragraph(f"The verdict rests on {v.compared} of {v.asked} load levels: the others "
                      "did not converge on one barrier or both (above); `make` exits 3.")
    p, m = v.prototype.deformation, v.model.deformation
    idx = [int(np.argmin(np.abs(p.levels - x))) for x in SHAPE_LEVELS]
    rows = []
    for mm in v.mismatches:
        rows.append([f"{METRICS[mm.metric]} ({unit_of(mm.metric)})"]
                    + [f"{fmt_value(mm.metric, p.values[mm.metric][i])} / "
                       f"{fmt_value(mm.metric, m.values[mm.metric][i])}" for i in idx]
                    + [f"{mm.max_rel:.0%}", f"{mm.rms_rel:.0%}", f"{mm.ratio_high:.2f}",
                       "ok" if mm.ok else "FAIL"])
    rep.table(["quantity (prototype / model)", "h/h_B = 0.5", "1.0", "1.1", "max mismatch",
               "RMS", "model/proto above 0.8", ""], rows)
    if v.from_start:
        rep.paragraph("Counted from h/h_B = 0, as extension sensors zeroed before the water "
                      "arrives read it:")
        rep.table(["quantity", "max mismatch", "RMS", "model/proto above 0.8", ""],
                  [[METRICS[mm.metric], f"{mm.max_rel:.0%}", f"{mm.rms_rel:.0%}",
                    f"{mm.ratio_high:.2f}", "ok" if mm.ok else "FAIL"] for mm in v.from_start])
    rep.table(["max tension at h/h_B = 1.1", "prototype (kN)", f"model x {scale:g}^3 (kN)",
               "model (N)"],
              [["net strands", f"{p.max_strand_tension[-1] / 1e3:.1f}",
                f"{to_prototype(m.max_strand_tension[-1], FORCE_EXPONENT, scale) / 1e3:.1f}",
                f"{m.max_strand_tension[-1]:.3g}"],
               ["border cables", f"{p.max_cable_tension[-1] / 1e3:.1f}",
                f"{to_prototype(m.max_cable_tension[-1], FORCE_EXPONENT, scale) / 1e3:.1f}",
                f"{m.max_cable_tension[-1]:.3g}"]])
    title = "Normalised deformation against relative loading"
    # cost: CPU seconds of each drawing (bench timeline, simple barrier 1:40; Drawing.cost)
    rep.figure(Drawing(verification_figure, (p, m, scale, title), {"band": band}, cost=2.0),
               "Prototype (black) and printed model (orange"
               + ("; shaded: the model's uncertainty band)." if band is not None else ")."),
               "verification")
    _deformed_section(rep, v)
    _sensor_section(rep, v)
    rep.paragraph(f"Solver: {sum(v.prototype.iterations)} + {sum(v.model.iterations)} Newton "
                  f"iterations over {len(p.levels)} load levels (times in timings.json).",
                  "note")


def unit_of(metric: str) -> str:
    """The unit a METRICS quantity is shown in: strains in %, the rest normalised (-)."""
    return "%" if metric.startswith("strain") else "-"


def fmt_value(metric: str, x: float) -> str:
    """A METRICS value as shown: strains in % (2 decimals), the rest to 4 decimals."""
    return f"{x * 100:.2f}" if metric.startswith("strain") else f"{x:.4f}"


def _deformed_section(rep: Report, v: Verification) -> None:
    from printgen.report.plots import deformed_figure

    shapes = [(f"{who}: {run.scene.name}", run.scene, run.shapes[SHOWN_LEVEL])
              for who, run in (("prototype", v.prototype), ("model", v.model))
              if SHOWN_LEVEL in run.shapes]
    if len(shapes) == 2:
        rep.figure(Drawing(deformed_figure, (shapes, SHOWN_LEVEL), cost=1.0),
                   "Both nets deformed at h/h_B = "
                   f"{SHOWN_LEVEL:g}, normalised by their own width (x, deflection) and height "
                   "(z); black: border cables. Model node positions at 0.5, 1.0 and 1.1 are in "
                   "report.json (verification.deformed_shape).", "deformed-nets")
    for who, run in (("prototype", v.prototype), ("model", v.model)):
        if run.scene.hold > 0:
            rep.paragraph(f"{who}: unloaded strands stay where they are (held by "
                          f"{run.scene.hold:.3g} N/m per node); the hold carries at most "
                          f"{run.hold_share:.2%} of the applied load at any level.", "note")


def _sensor_section(rep: Report, v: Verification) -> None:
    """The sensors' share of the model's water load at each level (report.json:
    verification.sensors)."""
    s = v.sensors
    if s is None:
        return
    rep.paragraph(f"Sensors: {s.text()}. Share = {s.count} wires x their pull / the "
                  "hydrostatic resultant on the model's net (rho g sum(h - z) A*); threshold "
                  f"{s.threshold:.0%} at h/h_B = {s.level:g}.", "note")
    shown = [i for i, lv in enumerate(s.levels)  # every 0.1, as the other tables
             if lv > 0 and abs(lv * 10 - round(lv * 10)) < 1e-9]
    rep.table(["h/h_B", "water load on the model (N)", "sensors' pull / water load"],
              [[f"{s.levels[i]:g}", f"{s.load_n[i]:.3g}", f"{s.shares[i]:.1%}"]
               for i in shown])


def _assumption_tables(rep: Report, v: Verification) -> None:
    for who, run in (("prototype", v.prototype), ("model", v.model)):
        rep.table([f"{who}: what", "value", "source"], [list(a) for a in run.scene.assumptions])


def _small(x: float, noise: float = 1e-9) -> str:
    return "0" if abs(x) < noise else f"{x:.3g}"  # solver round-off at h = 0


def load_case_sections(rep: Report, v: Verification) -> None:
    """`make --loads`: each load case's assumptions and the printed model's expected readings
    at its own levels (nominal; the files expected-readings-<case>.csv)."""
    if not v.by_load:
        return
    rep.heading("What the campaign will see: expected readings by load case")
    rep.paragraph("The nominal printed model (and prototype) under each case of --loads, at "
                  "the case's own levels (the jam: the flume's discharge steps); no band. "
                  "Files: expected-readings-<case>.csv.")
    for name, c in v.by_load.items():
        rows = [list(a) for a in c.model.scene.assumptions if a[0].startswith("loading")]
        rep.table([f"{c.spec}: what", "value", "source"], rows)
        d, used = c.model.deformation, c.load.get("model", {})
        q = used.get("discharge_l_per_s", used.get("velocity_m_per_s"))
        head = "discharge (L/s)" if "discharge_l_per_s" in used else "velocity (m/s)"
        table = [[f"{lv:.3f}", "" if q is None else f"{q[i]:.3g}",
                  f"{100 * d.values['strain_mid'][i]:.2f}", f"{d.values['deflection'][i]:.4f}",
                  _small(d.max_cable_tension[i])] for i, lv in enumerate(d.levels)]
        rep.table([f"{name}: h/h_B", head, "mid-height strain (%)", "deflection / width",
                   "max cable tension (N)"], table)


def _counterexample_section(rep: Report, ce: CounterExample) -> None:
    rep.heading("Why stiffness is scaled: steel at every scale")
    rep.paragraph(
        "The simple barrier (12 x 4 m, square 0.2 m mesh of 10 mm steel strands, bottom and "
        "sides anchored, top free) under hydrostatic load at h = h_B: with E scaled by 1/lambda "
        "the model deforms exactly like the prototype; with steel at the model scale it barely "
        "deflects - the wall-like model this tool exists to avoid.")
    rep.table(["variant", "deflection / width", "lowering / height"],
              [[k, f"{ce.deflection[k]:.4f}", f"{ce.lowering[k]:.4f}"] for k in ce.deflection])
