"""The report's summary box, first on the page: the verdict and its reason, the band verdict,
the chosen materials and sections with their stiffness error, print time and mass, and what
to do next. Built from the run's records (printgen.report.records); the box, report.json's
"summary" and the terminal's lines are that one `Summary`, so they say the same."""

from __future__ import annotations

import html
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from printgen.barrier.patterns import mesh_text
from printgen.verification.bands import band_verdicts
from printgen.verification.compare import METRICS

if TYPE_CHECKING:  # pragma: no cover
    from printgen.report.records import GcodeRecord, PlanRecords, RunRecords
    from printgen.scaling.record import Design, Section
    from printgen.scaling.selection import Candidate

NEXT_PASS = ("Print the parts (the .gcode files, or slice the .3mf files), assemble them as the "
             "Assembly section below shows, and run the flume test with measurement-sheet.csv; "
             "bring the readings back with printgen verify --measured.")
NEXT_STIFF = ("Change the net before printing: the model is too stiff. Try a softer material, "
              "fewer passes or a thinner strand (printgen select lists them), or let printgen "
              "design search the net (--objective deformation), then make again.")
NEXT_SOFT = ("Change the net before printing: the model is too soft. Try a stiffer material or "
             "more passes (printgen select), or printgen design, then make again.")
NEXT_UNDECIDED = ("Settle what decides before printing: {test}; then verify again (printgen "
                  "verify --design, with the answer in the prototype file or the profile).")
NEXT_NONE = "Run make with the verification step to get the verdict before printing."
NEXT_FLUME = ("Change the scale or the flume before printing: {fix}. Then make again at that "
              "scale (the parts are selected anew for it).")
NEXT_SENSORS = ("Keep the net: it matches the prototype once the prototype's sensors pull as "
                "much of its load. Use weaker sensors: set flume.sensor_force_n <= {limit:.2g} "
                "N in the prototype file (each wire's pull; the sensors' share of the water "
                "load at h/h_B = {level:g} is then at most {share:.0%}), then make again.")


def print_rows(gcode: dict[str, GcodeRecord]) -> tuple[list[str], list[list[str]]]:
    """(columns, rows) of the print-time table: each part and the total."""
    from printgen.parts.gcode.estimate import NOT_COUNTED, duration

    rows, tot = [], {"print_time_s": 0.0, "filament_mm": 0.0, "mass_g": 0.0}
    for name, rec in gcode.items():
        p = rec.estimate.to_record()
        rows.append([name, duration(p["print_time_s"]), f"{p['filament_mm'] / 1e3:.3f}",
                     f"{p['mass_g']:.2f}"])
        for k in tot:
            tot[k] += p[k]
    rows.append(["total", duration(tot["print_time_s"]), f"{tot['filament_mm'] / 1e3:.3f}",
                 f"{tot['mass_g']:.2f}"])
    return ([f"part (print time: {NOT_COUNTED})", "print time", "filament (m)", "mass (g)"],
            rows)


def print_totals(gcode: dict[str, GcodeRecord]) -> dict[str, float]:
    """Total print time (s), filament (mm) and mass (g) over every part's G-code."""
    prints = [r.estimate.to_record() for r in gcode.values()]
    keys = ("print_time_s", "filament_mm", "mass_g")
    return {k: float(sum(p[k] for p in prints)) for k in keys}


@dataclass(frozen=True)
class Summary:
    """The summary's numbers: verdict and reason (its sentences one per line), the band
    verdict of each metric, the chosen parts, print totals (None: no G-code), the next step
    and the targets' warnings that the verdict does not already say (report.json
    "summary")."""

    verdict: str
    reason: str
    band: dict[str, str]
    parts: list[dict[str, Any]]
    next: str
    print: dict[str, float] | None = None
    warnings: list[str] = field(default_factory=list)
    sensors: str = ""  # the sensors' share of the model's water load, one sentence

    def to_record(self) -> dict[str, Any]:
        out: dict[str, Any] = {"verdict": self.verdict, "reason": self.reason,
                               "band": self.band, "parts": self.parts, "next": self.next,
                               "warnings": self.warnings}
        if self.print is not None:
            out["print"] = self.print
        if self.sensors:
            out["sensors"] = self.sensors
        return out


def summarize(run: RunRecords, next_step: str = "") -> Summary:
    """The run's summary, from its records (`next_step` replaces the one chosen from the
    verdict)."""
    check, gcode = run.check, run.steps.get("gcode")
    sensors = ""
    if check is None:
        verdict, reason, band, nxt = "not run", "", {}, NEXT_NONE
    else:
        v = check.verification
        verdict, reason = v.verdict, v.headline
        band = {b.metric: b.text for b in band_verdicts(v.prototype.deformation.values,
                                                        check.band)
                if b.levels > 0}  # none where nothing deforms
        ratios = [m.ratio_high for m in v.mismatches if not m.ok]
        nxt = NEXT_PASS if v.ok else (NEXT_STIFF if ratios and min(ratios) < 1 else NEXT_SOFT)
        undecided = (NEXT_UNDECIDED.format(test=v.decision.test)
                     if v.verdict == "UNDECIDED" and v.decision is not None else "")
        nxt = undecided or nxt
        if v.sensors is not None:
            sensors = v.sensors.text()
            if v.sensors_to_blame:  # the net is similar: the sensors, not the material
                nxt = NEXT_SENSORS.format(limit=v.sensors.limit_n, level=v.sensors.level,
                                          share=v.sensors.threshold)
        advice = run.steps.get("advice")
        if advice is not None and advice.next:  # a change printgen verified, or why none
            nxt = (f"{undecided} With the nominal inputs: {advice.next}" if undecided
                   else advice.next)
        if not v.runnable and v.flow is not None:  # a new scale changes the parts too
            nxt = NEXT_FLUME.format(fix=v.flow.fix)
    return Summary(verdict, reason, band, chosen_parts(run.design, run.plan,
                                                       run.steps.get("design_net")),
                   next_step or nxt, print_totals(gcode) if gcode else None,
                   _warnings(run), sensors)


def _warnings(run: RunRecords) -> list[str]:
    """The targets' warnings (the model flow's, a printed mesh chosen for another scale), but
    the flume's limits the verdict states."""
    if run.plan is None:
        return []
    t = run.plan.targets
    stated = {lim.text for lim in t.flow.limits} if run.check is not None else set()
    return [w for w in t.warnings if w not in stated]


def chosen_parts(design: Design, plan: PlanRecords | None = None,
                 own_net: Candidate | None = None) -> list[dict[str, Any]]:
    """The net and the border cables as chosen: material, section, passes, stiffness error
    (the selection's candidate of the same section; a design file's net: its own, `own_net`
    when there is no plan)."""
    sel = None if plan is None else plan.selection
    net = design.net
    pick = plan.own_net if plan is not None and plan.own_net is not None else (
        own_net if sel is None else _same_section(sel.net, net.material, net.strand))
    out = [{"part": "net", "material": net.material.upper(),
            "section": (f"strand {_mm(net.strand)}, "
                        + mesh_text(net.pattern, net.mesh_x_mm, net.mesh_y_mm)),
            "stiffness_error": None if pick is None else pick.error,
            "stiffness_error_across": None if pick is None else pick.error_across,
            "stiffness_error_up": None if pick is None else pick.error_up}]
    if design.cables:
        c = design.cables[0]
        pick = None if sel is None else _same_section(sel.cables, c.material, c.section)
        out.append({"part": f"border cables ({len(design.cables)})",
                    "material": c.material.upper(), "section": _mm(c.section),
                    "stiffness_error": None if pick is None else pick.error})
    return out


def _mm(s: Section) -> str:
    w, t, n = _dims(s)
    return f"{w:g} x {t:g} mm, {n} passes"


def _dims(s: Section) -> tuple[float, float, int]:
    """(width mm, thickness mm, passes) of a section, rounded as design.json states them."""
    layers = s.layer_heights_mm
    return (round(s.bead_width_mm * s.beads_across, 6), round(float(sum(layers)), 6),
            s.beads_across * len(layers))


def _same_section(ranked: tuple[Candidate, ...], material: str, s: Section
                  ) -> Candidate | None:
    w, t, n = _dims(s)
    for c in ranked:
        cs = c.section
        if (c.material == material and cs.passes == n
                and abs(cs.width_mm - w) < 1e-9 and abs(cs.thickness_mm - t) < 1e-9):
            return c
    return None


def _stiffness_text(part: dict[str, Any]) -> str:
    """', stiffness +521% across, +182% up off target' (a net: both barrier directions)."""
    if part.get("stiffness_error_across") is not None:
        return (f", stiffness {part['stiffness_error_across']:+.0%} across and "
                f"{part['stiffness_error_up']:+.0%} up off target")
    if part["stiffness_error"] is None:
        return ""
    return f", stiffness {part['stiffness_error']:+.0%} off target"


def summary_html(s: Summary) -> str:
    """The summary box (HTML)."""
    from printgen.parts.gcode.estimate import duration

    e = html.escape
    tag = s.verdict.lower() if s.verdict in ("PASS", "FAIL", "UNDECIDED") else "note"
    reason = "<br>".join(e(x) for x in (s.reason or "the verification was not run").split("\n"))
    lines = [f'<p class="verdict"><span class="{tag}">{e(s.verdict)}</span> {reason}</p>']
    lines += [f"<p><b>Warning:</b> {e(w)}</p>" for w in s.warnings]
    if s.band:
        lines.append("<p><b>Uncertainty band</b> (where the prototype lies against the "
                     "envelope of the model's variants):</p><ul>" + "".join(
                         f"<li>{e(METRICS[k].split(' (')[0])}: {e(t)}</li>"
                         for k, t in s.band.items()) + "</ul>")
    parts = "; ".join(
        f"{e(p['part'])}: {e(p['material'])}, {e(p['section'])}"
        + _stiffness_text(p) for p in s.parts)
    lines.append(f"<p><b>Chosen:</b> {parts}</p>")
    if s.sensors:
        lines.append(f"<p><b>Sensors:</b> {e(s.sensors)}</p>")
    if s.print is not None:
        t = s.print
        lines.append(f"<p><b>Printing:</b> {e(duration(t['print_time_s']))}, "
                     f"{t['filament_mm'] / 1e3:.2f} m of filament, {t['mass_g']:.1f} g "
                     "(all parts; per part in Direct G-code)</p>")
    lines.append(f"<p><b>Next:</b> {e(s.next)}</p>")
    return '<section class="summary" id="summary"><h2>Summary</h2>' + "".join(lines) \
        + "</section>"


def summary_lines(s: dict[str, Any]) -> list[str]:
    """The summary as plain lines for the terminal, from its record (report.json's
    "summary", which `make --json` prints too)."""
    from printgen.parts.gcode.estimate import duration

    if not s:
        return []
    out = [f"{s['verdict']}: {s['reason']}" if s["reason"] else s["verdict"]]
    if s.get("sensors") and s["sensors"] != s["reason"]:
        out.append(f"sensors: {s['sensors']}")
    if "print" in s:
        t = s["print"]
        out.append(f"printing: {duration(t['print_time_s'])}, {t['filament_mm'] / 1e3:.2f} m "
                   f"of filament, {t['mass_g']:.1f} g")
    out += [f"warning: {w}" for w in s.get("warnings", [])]
    out.append(f"next: {s['next']}")
    return out
