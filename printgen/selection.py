"""Choose a polymer and pass layout for the border cables (axial stiffness E*A) and for the net
(membrane law from the diamond geometry) against the similitude targets.

Every material x layout (beads side by side x stacked layers of the print style) is a
candidate. Each gets its stiffness error, the Pi3 deviation of its equivalent section, a
strength safety factor under the peak scaled load, its flow-limited print speed, and the
reasons it cannot be printed, if any. Measured printed moduli are preferred over datasheet ones.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from printgen.design import Section
from printgen.errors import DesignError, PrintabilityError
from printgen.laws import piecewise_linear
from printgen.materials import Material
from printgen.printers import PrintStyle, Printer, check_pass
from printgen.section import area_m2, equal_area_diameter, net_membrane_law
from printgen.similitude import ScaledTargets
from printgen.units import G

MAX_BEADS_ACROSS = {"cable": 6, "net": 2}  # wider strands are no longer "strands"
MAX_LAYERS = {"cable": 6, "net": 5}
MIN_SAFETY_FACTOR = 1.5  # peak-load estimate is rough: keep margin
DATASHEET_PENALTY = 0.10  # score added when only a datasheet modulus exists (~10 % error)
PASS_PENALTY = 0.002  # per pass: prefer shorter prints among equals
MIN_SPEED_MM_S = 2.0  # slower than this, the flow limit makes the print impractical
ASSUMED_SAG_RATIO = 0.2  # peak-force estimate: sag / span of a loaded cable or net strip
OVERFLOW = 1.1  # peak relative loading h / h_B of the loading test
NET_STRAINS = np.linspace(0.01, 0.40, 40)  # strain range over which net laws are compared
CHECK_STRAINS = (0.05, 0.30)  # net law errors reported at low and high strain


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

    @property
    def feasible(self) -> bool:
        return not self.reasons


@dataclass(frozen=True)
class Selection:
    """Ranked candidates (best first) and the rationale for each winner."""

    cables: tuple[Candidate, ...]
    net: tuple[Candidate, ...]
    cable_rationale: str
    net_rationale: str

    @property
    def cable(self) -> Candidate | None:
        return self.cables[0] if self.cables and self.cables[0].feasible else None

    @property
    def net_choice(self) -> Candidate:
        return self.net[0]


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


def peak_strand_force(t: ScaledTargets, mesh_across: float, mesh_along: float) -> float:
    """Estimated peak net-strand tension (N): a vertical net strip of span h_B under the
    bottom pressure at overflow, sag ratio ASSUMED_SAG_RATIO, shared by 2 / a strands."""
    s = ASSUMED_SAG_RATIO
    h_b = t["height"]
    n = 1000.0 * G * OVERFLOW * h_b * h_b / (8 * s) * math.sqrt(1 + 16 * s * s)
    sin = (mesh_along / 2) / math.hypot(mesh_along / 2, mesh_across / 2)
    return n * mesh_across / (2 * sin)


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


def target_net_law(t: ScaledTargets, proto_net_factor: float) -> tuple[tuple, tuple]:
    """(knees, membrane slopes N/m) of the model net target."""
    knees = tuple(r.prototype for r in ())  # placeholder-free: filled below
    membranes = [t.values[k] for k in sorted(t.values) if k.startswith("membrane_")]
    if membranes:
        knees = t.knees
        return knees, tuple(membranes)
    return (), (t["strand_ea"] * proto_net_factor,)
