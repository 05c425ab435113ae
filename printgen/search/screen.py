"""Stage 1 of `printgen design`: screen every candidate net by the analytic membrane law.

For one `NetPoint`: the membrane law of its pattern's geometry (`section.net_membrane_law`)
against the target law over 1-40 % strain, along the load and across it (RMS log error over
both: a net flattened to soften it along the load stiffens across it), its small-strain error,
and the constraints: safety factor >= `MIN_SAFETY_FACTOR` at the estimated overflow strand force,
printable passes and flow (`selection.print_limits`), the panel fits the bed, clear mesh opening
>= `MIN_OPENING_MM`. Also the similitude it breaks (Pi2: mesh / h_B for both diagonals; Pi3:
equal-area strand diameter / h_B) and an estimate of its print time.

`screen_batch` is a pure function of (context, points): a sweep task.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from printgen.inputs.laws import piecewise_linear
from printgen.scaling.record import Section
from printgen.scaling.section import area_m2, equal_area_diameter, net_membrane_law
from printgen.scaling.selection import (
    DATASHEET_PENALTY,
    MIN_SAFETY_FACTOR,
    NET_STRAINS,
    peak_strand_force,
    print_limits,
    target_net_laws,
)
from printgen.search.space import NetPoint, SearchContext
from printgen.units import MM

MIN_OPENING_MM = 2.0  # clear mesh opening: narrower holes fuse when printed and pass no water
CONSTRAINTS = ("strength", "print", "bed", "opening")  # kinds a candidate can violate


@dataclass(frozen=True)
class Screened:
    """A screened candidate: analytic law error, constraints, similitude break, print time.

    Errors are relative (model / target - 1) except `error_rms_log`; `d_pi2` is the larger
    relative deviation of the two mesh diagonals from the scaled prototype's, with its sign;
    `violations` are (kind in CONSTRAINTS, message) pairs, empty when printable.
    """

    point: NetPoint
    law_source: str
    datasheet: bool
    membrane_n_per_m: float  # small-strain membrane stiffness, in the worse direction
    target_n_per_m: float
    error_small: float  # in the worse of the two directions below (by |log|)
    error_rms_log: float
    score: float
    peak_force_n: float
    safety_factor: float
    speed_mm_per_s: float
    opening_mm: float
    d_pi2: float
    d_pi3: float
    print_time_s: float
    violations: tuple[tuple[str, str], ...]
    error_across: float = 0.0  # small-strain membrane stiffness / target - 1, across the barrier
    error_up: float = 0.0  # ... up the barrier

    @property
    def feasible(self) -> bool:
        return not self.violations

    def to_record(self) -> dict:
        """JSON-ready record (stable keys)."""
        p = self.point
        return {
            "index": p.index, "material": p.material, "beads_across": p.beads_across,
            "layers": p.layers, "mesh_x_mm": p.mesh_x_mm, "mesh_y_mm": p.mesh_y_mm,
            "half_cells": [p.half_cells_x, p.half_cells_y], "border_beads": p.border_beads,
            "pattern": p.pattern,
            "law_source": self.law_source, "datasheet": self.datasheet,
            "membrane_n_per_m": self.membrane_n_per_m, "target_n_per_m": self.target_n_per_m,
            "error_small_strain": self.error_small, "error_rms_log": self.error_rms_log,
            "stiffness_error_across": self.error_across, "stiffness_error_up": self.error_up,
            "score": self.score, "peak_force_n": self.peak_force_n,
            "safety_factor": self.safety_factor, "speed_mm_per_s": self.speed_mm_per_s,
            "opening_mm": self.opening_mm, "d_pi2": self.d_pi2, "d_pi3": self.d_pi3,
            "print_time_s": self.print_time_s, "feasible": self.feasible,
            "violations": [{"constraint": k, "reason": r} for k, r in self.violations],
        }


def strand_section(ctx: SearchContext, point: NetPoint) -> Section:
    """The candidate's strand: `beads_across` beads of the style x `layers` stacked layers."""
    s = ctx.style
    return Section(s.bead_width_mm, point.beads_across, tuple(s.layer_heights_mm(point.layers)))


def clear_opening_mm(mesh_x_mm: float, mesh_y_mm: float, strand_width_mm: float,
                     pattern: str = "diamond") -> float:
    """Clear distance between parallel strands (mm): the square's side, the diamond's rhombus
    height (area a_x a_y / 2 over its side), less one strand width."""
    if pattern == "square":
        return mesh_x_mm - strand_width_mm
    side = math.hypot(mesh_x_mm / 2, mesh_y_mm / 2)
    return mesh_x_mm * mesh_y_mm / (2 * side) - strand_width_mm


def print_time_s(ctx: SearchContext, point: NetPoint, sec: Section, speed: float) -> float:
    """Extrusion time of the net (s): every diagonal strand piece (one per half-cell
    rectangle) and the border frame, bead by bead and layer by layer, at the flow-limited
    speed. Travel moves are not counted: this ranks candidates, it is not a slicer's estimate."""
    px, py = point.mesh_x_mm / 2, point.mesh_y_mm / 2
    diagonals = point.half_cells_x * point.half_cells_y * math.hypot(px, py)
    if point.pattern == "square":  # the inner strands across and up (the edges: the border)
        w, h = point.mesh_x_mm * point.half_cells_x / 2, point.mesh_y_mm * point.half_cells_y / 2
        diagonals = (point.half_cells_x / 2 - 1) * h + (point.half_cells_y / 2 - 1) * w
    border = 2 * (ctx.width_mm + ctx.height_mm)
    per_layer = sec.beads_across * diagonals + point.border_beads * border
    return len(sec.layer_heights_mm) * per_layer / speed


def bed_violation(ctx: SearchContext, point: NetPoint, bead_mm: float) -> str | None:
    """Why the panel (with its border frame) does not fit the bed, axis-aligned or turned."""
    pr = ctx.printer
    w = ctx.width_mm + point.border_beads * bead_mm
    h = ctx.height_mm + point.border_beads * bead_mm
    bx, by = pr.bed_x_mm - 2 * pr.bed_margin_mm, pr.bed_y_mm - 2 * pr.bed_margin_mm
    if (w <= bx and h <= by) or (w <= by and h <= bx):
        return None
    return (f"net {w:.0f} x {h:.0f} mm does not fit the {bx:.0f} x {by:.0f} mm usable bed of "
            f"{pr.key}; use a larger scale (lambda) or a larger printer")


def across_law(knees: tuple[float, ...], slopes: tuple[float, ...], mesh_along: float,
               mesh_across: float, pattern: str = "diamond"
               ) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """The membrane law of the same net loaded across. Diamond: a strand strains eps cos^2
    instead of eps sin^2 and 2 / a_along strands carry it, so with r = a_across / a_along
    (= cot theta) the knees scale by 1 / r^2 and the slopes by r^4. Square (a square mesh):
    the strands across are those along, the same law."""
    if pattern == "square":
        return tuple(knees), tuple(slopes)
    r = mesh_across / mesh_along
    return tuple(k / r**2 for k in knees), tuple(k * r**4 for k in slopes)


def target_curve(ctx: SearchContext) -> tuple[float, np.ndarray]:
    """(small-strain target slope N/m up the barrier, target force per width N/m at
    NET_STRAINS up the barrier, then across it: the prototype's law read along the diagonal
    its source loaded, `target_net_laws`)."""
    laws = target_net_laws(ctx.prototype, ctx.targets)
    return laws["up"][1][0], np.concatenate([piecewise_linear(NET_STRAINS, *laws["up"]),
                                             piecewise_linear(NET_STRAINS, *laws["across"])])


@dataclass(frozen=True)
class NetLaw:
    """What a candidate's screening shares with every border width of the same net (material,
    section, mesh, pattern): its membrane laws against the target, constraints but the bed's,
    similitude break. `screen_batch` computes it once per net."""

    source: str
    datasheet: bool
    slope: float  # small-strain membrane stiffness in the worse direction, N/m
    worse: float
    rms: float
    force: float
    safety_factor: float
    speed: float
    opening: float
    d_pi2: float
    d_pi3: float
    violations: tuple[tuple[str, str], ...]
    across: float
    up: float


def net_law(ctx: SearchContext, point: NetPoint, target: tuple[float, np.ndarray],
            force: float | None = None) -> NetLaw:
    """The border-independent part of `screen_point` (see the module); `force`: the
    estimated peak strand force (N) of its mesh (`peak_strand_force`), computed when not
    given."""
    t, m = ctx.targets, ctx.material(point.material)
    _, want = target
    sec = strand_section(ctx, point)
    ax, ay = point.mesh_x_mm * MM, point.mesh_y_mm * MM
    knees, slopes, source = net_membrane_law(m, sec, ay, ax, point.pattern)
    k2, s2 = across_law(knees, slopes, ay, ax, point.pattern)
    ratio = np.concatenate([piecewise_linear(NET_STRAINS, knees, slopes),
                            piecewise_linear(NET_STRAINS, k2, s2)]) / want
    rms = float(np.sqrt(np.mean(np.log(ratio) ** 2)))
    datasheet = source != "measured panel law" and m.modulus()[1] == "datasheet"
    where = f"net {m.name} strand {sec.width_mm:g}x{sec.thickness_mm:g} mm"
    speed, print_reasons = print_limits(sec, m, ctx.printer, where)
    violations = [("print", r) for r in print_reasons]
    force = peak_strand_force(t, ax, ay, point.pattern) if force is None else force
    sf = m.failure_stress()[0] * area_m2(sec) / force
    if sf < MIN_SAFETY_FACTOR:
        violations.append(("strength", (f"{where}, mesh {point.mesh_x_mm:.4g} x "
                                       f"{point.mesh_y_mm:.4g} mm: safety factor {sf:.2f} below "
                                       f"{MIN_SAFETY_FACTOR} at {force:.3g} N (overflow)")))
    opening = clear_opening_mm(point.mesh_x_mm, point.mesh_y_mm, sec.width_mm, point.pattern)
    if opening < MIN_OPENING_MM:
        violations.append(("opening", (f"clear mesh opening {opening:.2f} mm below "
                                      f"{MIN_OPENING_MM:g} mm; use a larger mesh or a thinner "
                                      "strand")))
    dx, dy = ax / t["mesh_x"] - 1, ay / t["mesh_y"] - 1
    # both directions at the first strain, on every law's first segment: the small-strain ratio
    up, across = float(ratio[0] - 1), float(ratio[len(NET_STRAINS)] - 1)
    worse = up if abs(math.log1p(up)) >= abs(math.log1p(across)) else across
    slope = slopes[0] if worse is up else s2[0]
    return NetLaw(source, datasheet, slope, worse, rms, force, sf, speed, opening,
                  dx if abs(dx) >= abs(dy) else dy,
                  equal_area_diameter(sec) / t["strand_d"] - 1, tuple(violations), across, up)


def screen_point(ctx: SearchContext, point: NetPoint,
                 target: tuple[float, np.ndarray] | None = None,
                 law: NetLaw | None = None) -> Screened:
    """Analytic membrane law, constraints and similitude break of one candidate
    (`target`: `target_curve(ctx)`, computed here when not given; `law`: its `net_law`,
    likewise)."""
    n = law or net_law(ctx, point, target or target_curve(ctx))
    sec = strand_section(ctx, point)
    violations = list(n.violations)
    bed = bed_violation(ctx, point, sec.bead_width_mm)
    if bed:  # in the order the constraints were always listed: print, strength, bed, opening
        at = sum(1 for k, _ in violations if k in ("print", "strength"))
        violations.insert(at, ("bed", bed))
    return Screened(point, n.source, n.datasheet, n.slope, n.slope / (1 + n.worse), n.worse,
                    n.rms, n.rms + DATASHEET_PENALTY * n.datasheet, n.force, n.safety_factor,
                    n.speed, n.opening, n.d_pi2, n.d_pi3,
                    print_time_s(ctx, point, sec, n.speed), tuple(violations), n.across, n.up)


def screen_batch(ctx: SearchContext, points: list[NetPoint]) -> list[Screened]:
    """`screen_point` over a batch (a sweep task: pure, ordered like `points`): the law of
    each net once, shared by its border widths (the grid's innermost factor), and the peak
    strand force of each mesh once, shared by every material and section."""
    target = target_curve(ctx)
    laws: dict[tuple, NetLaw] = {}
    forces: dict[tuple, float] = {}
    out = []
    for p in points:
        key = (p.material, p.beads_across, p.layers, p.mesh_x_mm, p.mesh_y_mm, p.pattern)
        law = laws.get(key)
        if law is None:
            mesh = key[3:]
            if mesh not in forces:
                forces[mesh] = peak_strand_force(ctx.targets, p.mesh_x_mm * MM, p.mesh_y_mm * MM,
                                                 p.pattern)
            law = laws[key] = net_law(ctx, p, target, forces[mesh])
        out.append(screen_point(ctx, p, target, law))
    return out
