"""Choose a polymer and pass layout for the border cables (axial stiffness E*A) and for the net
(membrane law from the printed pattern's geometry, `printed_pattern`) against the similitude
targets.

Every material x layout (beads side by side x stacked layers of the print style) is a
candidate. Each gets its stiffness error, the Pi3 deviation of its equivalent section, a
strength safety factor under the peak scaled load, its flow-limited print speed, and the
reasons it cannot be printed, if any. Measured printed moduli are preferred over datasheet ones.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from printgen.barrier.loads import OVERFLOW  # peak relative loading of the loading test
from printgen.barrier.patterns import AS_DRAWN, get_pattern, mesh_text
from printgen.errors import InputError, PrintabilityError
from printgen.inputs.laws import piecewise_linear
from printgen.inputs.materials import Material, load_material, material_names
from printgen.inputs.printers import Printer, PrintStyle, check_pass, load_print_style, load_printer
from printgen.inputs.prototype import Prototype
from printgen.outputs.display import Shown, Summary
from printgen.scaling.reading import PROTOTYPE_ORIENTATION, panel_axes, panel_reading
from printgen.scaling.record import NetDesign, Section
from printgen.scaling.section import (
    area_m2,
    equal_area_diameter,
    membrane_law_between,
    net_membrane_law,
)
from printgen.scaling.similitude import ScaledTargets
from printgen.units import MM, G

DEFAULT_PRINTER = "generic-350"
DEFAULT_NET_PRINT = "net-3pass"
DEFAULT_CABLE_PRINT = "cable-4pass"

MAX_BEADS_ACROSS = {"cable": 6, "net": 2}  # wider strands are no longer "strands"
MAX_LAYERS = {"cable": 6, "net": 5}
MIN_SAFETY_FACTOR = 1.5  # peak-load estimate is rough: keep margin
DATASHEET_PENALTY = 0.10  # score added when only a datasheet modulus exists (~10 % error)
PASS_PENALTY = 0.002  # per pass: prefer shorter prints among equals
SCORE_DIGITS = 9  # scores equal to 1e-9 are ties (same E*A, different layout)
MIN_SPEED_MM_S = 2.0  # slower than this, the flow limit makes the print impractical
ASSUMED_SAG_RATIO = 0.2  # peak-force estimate: sag / span of a loaded cable or net strip
CALIBRATE_FIRST = ("print the test pieces (printgen testpieces with its design file: strand "
                   "coupons and a net panel) and calibrate before printing the barrier "
                   "(printgen calibrate, then printgen verify)")
NET_STRAINS = np.linspace(0.01, 0.40, 40)  # strain range over which net laws are compared
CHECK_STRAINS = (0.05, 0.30)  # net law errors reported at low and high strain
NET_ON_TARGET = 0.30  # a net within +-30 % of the small-strain target is on target (as design)


@dataclass(frozen=True)
class Candidate:
    """One material x pass layout. Errors are signed relative (cable: E*A; net: law at
    CHECK_STRAINS) plus, for nets, the RMS log error over NET_STRAINS."""

    component: str
    material: str
    material_name: str
    modulus: float  # Pa, the one used
    modulus_source: str
    section: Section
    stiffness: float  # cable: E*A (N); net: initial membrane stiffness (N/m)
    target: float
    error: float
    error_low: float
    error_high: float
    error_rms: float
    pi3_deviation: float  # equal-area diameter / target diameter - 1
    peak_force: float  # N, per cable or per strand
    safety_factor: float
    speed_mm_per_s: float
    reasons: tuple[str, ...]
    score: float
    # nets: initial membrane stiffness (N/m) of the printed net and of the target loaded across
    # the barrier (along x) and up it (along z); None for cables
    stiffness_across: float | None = None
    stiffness_up: float | None = None
    target_across: float | None = None
    target_up: float | None = None

    @property
    def error_across(self) -> float | None:
        """Printed / target membrane stiffness across the barrier, minus 1 (nets)."""
        return _ratio(self.stiffness_across, self.target_across)

    @property
    def error_up(self) -> float | None:
        """Printed / target membrane stiffness up the barrier, minus 1 (nets)."""
        return _ratio(self.stiffness_up, self.target_up)

    def direction_text(self) -> str:
        """'+521 % across, +182 % up' (nets); '' for cables."""
        if self.error_across is None or self.error_up is None:
            return ""
        return f"{self.error_across:+.0%} across, {self.error_up:+.0%} up"

    def to_record(self) -> dict:
        """JSON-ready record of this candidate (stable keys)."""
        s = self.section
        return {
            "material": self.material, "material_name": self.material_name,
            "modulus_pa": self.modulus, "modulus_source": self.modulus_source,
            "section": {"bead_width_mm": s.bead_width_mm, "beads_across": s.beads_across,
                        "layer_heights_mm": list(s.layer_heights_mm), "width_mm": s.width_mm,
                        "thickness_mm": s.thickness_mm, "passes": s.passes},
            "stiffness": self.stiffness, "target": self.target, "error": self.error,
            "error_low_strain": self.error_low, "error_high_strain": self.error_high,
            "error_rms_log": self.error_rms, "pi3_deviation": self.pi3_deviation,
            "peak_force_n": self.peak_force, "safety_factor": self.safety_factor,
            "speed_mm_per_s": self.speed_mm_per_s, "feasible": self.feasible,
            "reasons": list(self.reasons), "score": self.score,
            "stiffness_across": self.stiffness_across, "stiffness_up": self.stiffness_up,
            "target_across": self.target_across, "target_up": self.target_up,
            "stiffness_error_across": self.error_across, "stiffness_error_up": self.error_up,
        }

    @property
    def feasible(self) -> bool:
        return not self.reasons

    def __repr__(self) -> str:
        """One line (a notebook prints it): material, section, stiffness error, printable."""
        s = self.section
        state = "printable" if self.feasible else f"not printable: {self.reasons[0]}"
        off = self.direction_text() or f"{self.error:+.0%}"
        return (f"Candidate({self.material} {s.width_mm:g} x {s.thickness_mm:g} mm, "
                f"{s.passes} passes, stiffness {off} of target, SF "
                f"{self.safety_factor:.2g}, {state})")


def _ratio(got: float | None, want: float | None) -> float | None:
    """got / want - 1, None when either is not given."""
    return None if got is None or want is None else got / want - 1


@dataclass(frozen=True)
class Selection(Shown):
    """Ranked candidates (best first) and the rationale for each winner."""

    cables: tuple[Candidate, ...]
    net: tuple[Candidate, ...]
    cable_rationale: str
    net_rationale: str
    printer: str
    net_print: str
    cable_print: str
    net_mesh: str = ""  # the printed net's pattern and mesh (`mesh_text`): what was priced

    @property
    def cable(self) -> Candidate | None:
        return self.cables[0] if self.cables and self.cables[0].feasible else None

    def __repr__(self) -> str:
        """A few lines (a notebook prints it, where the dataclass's own ran to 200 kB): the
        winners and how many were ranked; `to_record()` holds everything."""
        cable = repr(self.cables[0]) if self.cables else "none (no border cables)"
        return (f"Selection(printer {self.printer!r}, {self.net_mesh or 'net'}\n"
                f"  net ({len(self.net)} ranked): {self.net[0]!r}\n"
                f"  cables ({len(self.cables)} ranked): {cable})")

    def summary(self) -> Summary:
        """The winners, how many were ranked and why (the notebook's table)."""
        cable = repr(self.cables[0]) if self.cables else "none (no border cables)"
        return Summary(f"Selection (printer {self.printer})",
                       (("net", self.net_mesh or "-"),
                        (f"net, best of {len(self.net)}", repr(self.net[0])),
                        ("why", self.net_rationale),
                        (f"cables, best of {len(self.cables)}", cable),
                        ("why", self.cable_rationale)))

    def to_record(self) -> dict:
        """JSON-ready record of the ranked selection (stable keys)."""
        return {
            "printer": self.printer, "net_print": self.net_print, "cable_print": self.cable_print,
            "cable": {"rationale": self.cable_rationale,
                      "ranked": [c.to_record() for c in self.cables]},
            "net": {"mesh": self.net_mesh, "rationale": self.net_rationale,
                    "ranked": [c.to_record() for c in self.net]},
        }


def layouts(style: PrintStyle, component: str) -> list[Section]:
    """Every beads-across x layers section of this print style."""
    return [Section(style.bead_width_mm, n, tuple(style.layer_heights_mm(m)))
            for n in range(1, MAX_BEADS_ACROSS[component] + 1)
            for m in range(1, MAX_LAYERS[component] + 1)]


def print_limits(section: Section, material: Material, printer: Printer,
                 where: str) -> tuple[float, list[str]]:
    """(flow-limited speed mm/s, reasons it cannot be printed)."""
    reasons = []
    for h in set(section.layer_heights_mm):
        try:
            check_pass(printer, section.bead_width_mm, h, where=where)
        except PrintabilityError as exc:
            reasons.append(str(exc))
    bead_mm2 = section.bead_width_mm * max(section.layer_heights_mm)
    speed = min(material.print.print_speed_mm_per_s,
                material.print.max_volumetric_flow_mm3_per_s / bead_mm2)
    if speed < MIN_SPEED_MM_S:
        reasons.append(f"{where}: flow limit {material.print.max_volumetric_flow_mm3_per_s:g} "
                       f"mm^3/s allows only {speed:.2f} mm/s (< {MIN_SPEED_MM_S:g} mm/s)")
    return speed, reasons


def peak_cable_force(t: ScaledTargets) -> float:
    """Estimated peak border-cable tension (N) at overflow: top and bottom cables carry the
    net's load as parabolic cables of sag ratio ASSUMED_SAG_RATIO."""
    s = ASSUMED_SAG_RATIO
    h_b, w_b = t["height"], t["width"]
    total = 1000.0 * G * w_b * h_b**2 * (OVERFLOW - 0.5)
    q = total / (2 * w_b)
    return q * w_b / (8 * s) * math.sqrt(1 + 16 * s * s)


def printed_pattern(p: Prototype) -> str:
    """The pattern of the printed net: [model] pattern, else the prototype's (a pattern drawn
    as another, `AS_DRAWN`, is printed as that one: a water-drop net as a diamond)."""
    return p.model.pattern or AS_DRAWN.get(p.net.pattern, p.net.pattern)


def peak_strand_force(t: ScaledTargets, mesh_across: float, mesh_along: float,
                      pattern: str) -> float:
    """Estimated peak net-strand tension (N): a vertical net strip of span h_B under the
    bottom pressure at overflow, sag ratio ASSUMED_SAG_RATIO, shared by the strands of
    `pattern` (the diamond's 2 / a, the square's 1 / a)."""
    s = ASSUMED_SAG_RATIO
    h_b = t["height"]
    n = 1000.0 * G * OVERFLOW * h_b * h_b / (8 * s) * math.sqrt(1 + 16 * s * s)
    return get_pattern(pattern).strand_force(n, mesh_along, mesh_across)


def cable_candidate(t: ScaledTargets, m: Material, sec: Section, printer: Printer) -> Candidate:
    modulus, source = m.modulus()
    ea, target = modulus * area_m2(sec), t["cable_ea"]
    speed, reasons = print_limits(sec, m, printer, f"cable {m.name} {sec.beads_across}x"
                                  f"{len(sec.layer_heights_mm)}")
    force = peak_cable_force(t)
    sf = m.failure_stress()[0] * area_m2(sec) / force
    if sf < MIN_SAFETY_FACTOR:
        reasons.append(f"safety factor {sf:.2f} below {MIN_SAFETY_FACTOR} at {force:.2f} N")
    err = ea / target - 1
    score = (abs(math.log(ea / target)) + DATASHEET_PENALTY * (source == "datasheet")
             + PASS_PENALTY * sec.passes)
    return Candidate("cable", m.key, m.name, modulus, source, sec, ea, target, err, err, err,
                     abs(math.log(ea / target)), equal_area_diameter(sec) / t["cable_d"] - 1,
                     force, sf, speed, tuple(reasons), score)


def target_net_laws(p: Prototype, t: ScaledTargets
                    ) -> dict[str, tuple[tuple[float, ...], tuple[float, ...]]]:
    """(knee strains, membrane slopes N/m) of the model net's target force-per-width law loaded
    across the barrier ("across", along x) and up it ("up", along z).

    From the prototype's panel law (kappa * L_p scaled by lambda^-2), read along the diagonal
    its source loaded (PROTOTYPE_ORIENTATION) and carried to each direction through its
    strands (`membrane_law_between`); else from its strand E*A and mesh geometry (its
    pattern's `membrane_factor`).
    """
    net = get_pattern(p.net.pattern)
    ax, ay = t["mesh_x"], t["mesh_y"]
    if p.net.panel_law is None:
        return {"across": ((), (t["strand_ea"] * net.membrane_factor(ax, ay),)),
                "up": ((), (t["strand_ea"] * net.membrane_factor(ay, ax),))}
    knees, kappas = tuple(p.net.panel_law[0]), p.net.panel_law[1]
    slopes = tuple(t[f"membrane_{i}"] for i in range(len(kappas)))
    tested = (p.net.pattern, *panel_axes(ax, ay, PROTOTYPE_ORIENTATION))
    return {"across": membrane_law_between(knees, slopes, tested, (p.net.pattern, ax, ay)),
            "up": membrane_law_between(knees, slopes, tested, (p.net.pattern, ay, ax))}


def target_net_law(p: Prototype, t: ScaledTargets) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """(knee strains, membrane slopes N/m) of the model net's target law loaded up the barrier
    (along z, the printed net's `net_membrane_law(..., mesh_y, mesh_x)`): `target_net_laws`'s
    "up"."""
    return target_net_laws(p, t)["up"]


def model_mesh(p: Prototype, t: ScaledTargets) -> tuple[float, float]:
    """(mesh_x, mesh_y) of the printed net in m: the lab's choice, else the scaled mesh;
    GeometryError for a printed square net whose mesh is not square."""
    m = p.model
    mesh = ((m.mesh_x_mm * MM, m.mesh_y_mm * MM)
            if m.mesh_x_mm is not None and m.mesh_y_mm is not None else (t["mesh_x"], t["mesh_y"]))
    pattern = printed_pattern(p)
    get_pattern(pattern).check_mesh(*mesh, f"printed {pattern} net ([model] mesh_x_mm, "
                                    "mesh_y_mm)")
    return mesh


def net_candidate(p: Prototype, t: ScaledTargets, m: Material, sec: Section,
                  printer: Printer, *, mesh: tuple[float, float] | None = None,
                  pattern: str | None = None) -> Candidate:
    """Score one net candidate: its membrane law (the printed pattern's geometry) against the
    target law in both barrier directions, across and up (RMS log error over both); `mesh`
    (mesh_x, mesh_y in m, default `model_mesh`) and `pattern` (default `printed_pattern`) of a
    given design's net."""
    mesh_x, mesh_y = mesh or model_mesh(p, t)
    pattern = pattern or printed_pattern(p)
    dirs = {"across": (mesh_x, mesh_y), "up": (mesh_y, mesh_x)}
    laws = {k: net_membrane_law(m, sec, *dirs[k], pattern) for k in dirs}
    want_laws = target_net_laws(p, t)
    ratios = {k: piecewise_linear(NET_STRAINS, *laws[k][:2])
              / piecewise_linear(NET_STRAINS, *want_laws[k]) for k in dirs}
    # the worse direction at small strain is the one the single-number fields report
    worse = max(dirs, key=lambda k: abs(math.log(ratios[k][0])))
    low, high = (float(np.interp(s, NET_STRAINS, ratios[worse]) - 1) for s in CHECK_STRAINS)
    speed, reasons = print_limits(sec, m, printer, f"net {m.name} strand "
                                  f"{sec.width_mm:g}x{sec.thickness_mm:g} mm")
    force = peak_strand_force(t, mesh_x, mesh_y, pattern)
    sf = m.failure_stress()[0] * area_m2(sec) / force
    if sf < MIN_SAFETY_FACTOR:
        reasons.append(f"safety factor {sf:.2f} below {MIN_SAFETY_FACTOR} at {force:.3g} N")
    # both directions weigh alike: the barrier spans the flume across and holds the water up
    rms = float(np.sqrt(np.mean(np.log(np.concatenate(list(ratios.values()))) ** 2)))
    modulus, mod_source = m.modulus()
    source = laws["up"][2]
    measured = "measured" if source == "measured panel law" else mod_source
    score = rms + DATASHEET_PENALTY * (measured == "datasheet") + PASS_PENALTY * sec.passes
    got, want = laws[worse][1][0], want_laws[worse][1][0]
    return Candidate("net", m.key, m.name, modulus, source, sec, got, want,
                     float(ratios[worse][0] - 1), low, high, rms,
                     equal_area_diameter(sec) / t["strand_d"] - 1, force, sf, speed,
                     tuple(reasons), score, laws["across"][1][0], laws["up"][1][0],
                     want_laws["across"][1][0], want_laws["up"][1][0])


def design_net(p: Prototype, t: ScaledTargets, net: NetDesign, printer: str) -> Candidate:
    """A given design's own net (the design.json of `printgen design`) scored like select's
    candidates: its material, strand, mesh and pattern against the same target law."""
    return net_candidate(p, t, load_material(net.material), net.strand, load_printer(printer),
                         mesh=(net.mesh_x_mm * MM, net.mesh_y_mm * MM), pattern=net.pattern)


def net_print_name(p: Prototype, printer: Printer) -> str:
    """The net's print style (`print_style_name`)."""
    return print_style_name(p.model.net_print, p, printer, printer.net_print, DEFAULT_NET_PRINT)


def print_style_name(chosen: str | None, p: Prototype, printer: Printer, own: str,
                     default: str) -> str:
    """A part's print style: the prototype's [model] choice (`chosen`), made for its [model]
    printer; on another printer (--printer) that names a style for its nozzle (`own`), that
    one; else the bundled `default`."""
    if own and printer.key != (p.model.printer or printer.key):
        return own
    return chosen or own or default


def select(p: Prototype, t: ScaledTargets, *, printer: str | None = None,
           materials: tuple[str, ...] | None = None) -> Selection:
    """Rank every material x layout for cables and net; best feasible first."""
    printer_obj = load_printer(printer or p.model.printer or DEFAULT_PRINTER)
    mats = [load_material(n) for n in material_names(materials, p.model.materials)]
    net_style = load_print_style(net_print_name(p, printer_obj))
    cable_style = load_print_style(print_style_name(p.model.cable_print, p, printer_obj,
                                                    printer_obj.cable_print,
                                                    DEFAULT_CABLE_PRINT))
    for style, comp in ((net_style, "net"), (cable_style, "cable")):
        if style.component != comp:
            raise InputError(f"print style {style.key!r} is for {style.component}s, not {comp}s; "
                             f"pick a {comp} style (printgen profiles list)")
    nets = [net_candidate(p, t, m, s, printer_obj) for m in mats
            for s in layouts(net_style, "net")]
    cables = []
    if p.border is not None:
        cables = [cable_candidate(t, m, s, printer_obj) for m in mats
                  for s in layouts(cable_style, "cable")]
    cables, nets = _rank(cables), _rank(nets)
    if not any(c.feasible for c in nets):
        raise PrintabilityError(f"no material and pass layout can print the net on "
                                f"{printer_obj.key}: {nets[0].reasons[0]}")
    mesh_x, mesh_y = model_mesh(p, t)
    return Selection(tuple(cables), tuple(nets), _rationale(cables, "cable"),
                     _rationale(nets, "net") + _per_material(nets) + _readings(mats),
                     printer_obj.key,
                     net_style.key, cable_style.key,
                     mesh_text(printed_pattern(p), mesh_x / MM, mesh_y / MM))


def _per_material(ranked: list[Candidate]) -> str:
    """Sentences: each material's best printable net, and the first (best-ranked) net within
    +-NET_ON_TARGET at SF >= MIN_SAFETY_FACTOR, if any (with the prototype's scaled mesh)."""
    best: dict[str, Candidate] = {}
    for c in ranked:
        if c.feasible:
            best.setdefault(c.material_name, c)
    parts = [f"{name} {c.section.width_mm:g} x {c.section.thickness_mm:g} mm "
             f"({c.direction_text() or f'{c.error:+.0%}'}, SF {c.safety_factor:.1f})"
             for name, c in best.items()]
    out = " Best net per material: " + "; ".join(parts) + "."
    hit = next((c for c in ranked if c.feasible and abs(c.error) <= NET_ON_TARGET), None)
    if hit is None:
        return out + (f" No material gives a net within +-{NET_ON_TARGET:.0%} at the scaled "
                      "prototype mesh; printgen design also searches the mesh.")
    out += (f" First within +-{NET_ON_TARGET:.0%} at SF >= {MIN_SAFETY_FACTOR}: "
            f"{hit.material_name} {hit.section.width_mm:g} x {hit.section.thickness_mm:g} mm "
            f"({hit.direction_text()}).")
    return out + (f" It rests on a datasheet modulus: {CALIBRATE_FIRST}."
                  if hit.modulus_source == "datasheet" else "")


def _readings(mats: list[Material]) -> str:
    """Sentences: how each material's panel law is read (`printgen.scaling.reading`)."""
    readings = [r for r in map(panel_reading, mats) if r is not None]
    return "".join(f" {r.why()}." for r in readings)


def _rank(cands: list[Candidate]) -> list[Candidate]:
    # ties (same material, same passes) go to the squarest section: closest to a round cable
    def aspect(c: Candidate) -> float:
        w, t = c.section.width_mm, c.section.thickness_mm
        return max(w / t, t / w)

    return sorted(cands, key=lambda c: (not c.feasible, round(c.score, SCORE_DIGITS), aspect(c),
                                        c.material, c.section.passes))


def _rationale(ranked: list[Candidate], what: str) -> str:
    """One paragraph explaining the winner against the runner-up."""
    if not ranked:
        return f"The prototype has no border cables: no {what} to select."
    best = ranked[0]
    if not best.feasible:
        return f"No {what} can be printed: {best.reasons[0]}"
    sec = best.section
    layout = (f"{sec.beads_across} bead(s) of {sec.bead_width_mm:g} mm across x "
              f"{len(sec.layer_heights_mm)} layer(s) = {sec.width_mm:g} x {sec.thickness_mm:g} mm, "
              f"{sec.passes} passes")
    if what == "cable":
        fit = (f"E*A = {best.stiffness:.4g} N against the target {best.target:.4g} N "
               f"({best.error:+.1%})")
    else:
        fit = (f"membrane stiffness at small strain {best.stiffness_across:.4g} N/m across "
               f"the barrier against {best.target_across:.4g} N/m ({best.error_across:+.1%}) "
               f"and {best.stiffness_up:.4g} N/m up it against {best.target_up:.4g} N/m "
               f"({best.error_up:+.1%}); in the worse direction {best.error_low:+.0%} at "
               f"{CHECK_STRAINS[0]:.0%} and {best.error_high:+.0%} at {CHECK_STRAINS[1]:.0%} "
               f"strain (RMS log error {best.error_rms:.2f} over 1-40 %, both directions)")
    basis = ("a measured printed value" if "measured" in best.modulus_source else
             f"only a DATASHEET modulus (printed parts are often 2x softer): {CALIBRATE_FIRST}")
    others = [c for c in ranked[1:] if c.feasible and c.material != best.material]
    vs = (f" The best other material, {others[0].material_name}, scores {others[0].score:.3f} "
          f"against {best.score:.3f} ({others[0].direction_text() or f'{others[0].error:+.1%}'})."
          if others else "")
    return (f"{best.material_name}, {layout}: {fit}, based on {basis} "
            f"({best.modulus_source}). Its equal-area diameter breaks Pi3 (d / h_B) by "
            f"{best.pi3_deviation:+.0%}: the section is an equivalent one that keeps the "
            f"stiffness, not the geometric diameter. Safety factor {best.safety_factor:.1f} "
            f"against failure at the estimated peak force {best.peak_force:.3g} N (overflow "
            f"{OVERFLOW:.0%}); flow-limited speed {best.speed_mm_per_s:.3g} mm/s.{vs}")
