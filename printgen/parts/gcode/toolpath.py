"""Direct toolpaths for the diamond net and the eyelet cables (mm, mm/s).

A `Toolpath` is a set of parallel arrays, one row per move, in print order: the end point,
bead width and height, speed and flow fraction. Travel moves have width 0. `writer` turns
it into G-code text; `readback` turns G-code back into a `Toolpath`.

Net: each layer is one pass. The border (as many concentric loops as its width holds beads)
comes first, then every diagonal strand of one family as one straight extrusion from border
to border through the crossings, then the other family; the family order alternates from
layer to layer ("crossed passes"). The strands laid second in a layer cross beads already
there: over each crossing their flow is `crossing_flow_factor` (1 = full bead, the double
deposit at crossings stays).

Cable: per layer, the two eyelets as concentric rings, then the strip beads side by side
between the eyelets' outer circles. Long parts are turned on the bed (diagonal) if needed.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from printgen.design.record import CableDesign, NetDesign, Section
from printgen.errors import PrintabilityError, ProfileError
from printgen.inputs.materials import Material
from printgen.inputs.printers import Printer, PrintStyle, check_pass
from printgen.parts.geometry.net import NetGraph, diamond_net

TRAVEL, BORDER, STRAND_PLUS, STRAND_MINUS, CABLE_STRIP, EYELET = 0, 1, 2, 3, 4, 5
KIND_NAMES = {TRAVEL: "travel", BORDER: "border", STRAND_PLUS: "strand+",
              STRAND_MINUS: "strand-", CABLE_STRIP: "strip", EYELET: "eyelet"}
CHORD_TOL_MM = 0.01  # max distance of an eyelet polygon chord from the true circle
SPEED_MARGIN = 0.995  # speeds stay 0.5 % below the volumetric limit (written F is rounded)
N_ORIENTATIONS = 181  # bed placement tries angles 0..90 deg in 0.5 deg steps


@dataclass(frozen=True)
class Toolpath:
    """Moves of one part in print order; move i goes from row i-1 to row i.

    xyz_mm : (n, 3) float, mm, end point of each move (row 0 is a travel from anywhere)
    width_mm, height_mm : (n,) float, mm, bead width and height (0 on travel)
    speed_mm_per_s : (n,) float, mm/s
    flow : (n,) float, fraction of the full width x height section laid (0 on travel)
    layer : (n,) int, pass index; kind : (n,) int, TRAVEL / BORDER / STRAND_* / ...
    layer_z_mm : (k,) float, mm, top of each layer (nozzle height)
    """

    xyz_mm: np.ndarray
    width_mm: np.ndarray
    height_mm: np.ndarray
    speed_mm_per_s: np.ndarray
    flow: np.ndarray
    layer: np.ndarray
    kind: np.ndarray
    layer_z_mm: np.ndarray
    part: str = ""

    @property
    def extruding(self) -> np.ndarray:
        return (self.width_mm > 0) & (self.flow > 0)

    def lengths_mm(self) -> np.ndarray:
        """(n,) XY length of each move (0 for row 0)."""
        d = np.diff(self.xyz_mm[:, :2], axis=0)
        return np.concatenate([[0.0], np.hypot(d[:, 0], d[:, 1])])

    def area_mm2(self) -> np.ndarray:
        """(n,) deposited section per move (w x h x flow, rectangle), mm^2."""
        return np.where(self.extruding, self.width_mm * self.height_mm * self.flow, 0.0)

    def volume_per_layer_mm3(self) -> np.ndarray:
        v = self.area_mm2() * self.lengths_mm()
        return np.bincount(self.layer, weights=v, minlength=len(self.layer_z_mm))

    @property
    def volume_mm3(self) -> float:
        return float(np.sum(self.area_mm2() * self.lengths_mm()))

    def bounds_mm(self) -> np.ndarray:
        """(2, 3) min / max of the extrusion centre lines (start and end points)."""
        ext = np.flatnonzero(self.extruding)
        pts = self.xyz_mm[np.concatenate([ext, ext - 1])]
        return np.vstack([pts.min(axis=0), pts.max(axis=0)])


@dataclass(frozen=True)
class VolumeBudget:
    """Designed volumes of a part (mm^3), all layers.

    nominal : every bead at full section over its whole centre line
    crossing_overlap : strand on strand at the crossings (counted twice in `nominal`)
    junction_overlap : strand ends inside the border / strip ends in the eyelets
    solid : the part itself (nominal minus overlaps) - the mesh volume
    deposit : what the G-code lays: nominal minus the flow saved over crossings
    """

    nominal_mm3: float
    crossing_overlap_mm3: float
    junction_overlap_mm3: float
    crossing_flow_factor: float
    crossings_per_layer: int

    @property
    def solid_mm3(self) -> float:
        return self.nominal_mm3 - self.crossing_overlap_mm3 - self.junction_overlap_mm3

    @property
    def deposit_mm3(self) -> float:
        return self.nominal_mm3 - (1.0 - self.crossing_flow_factor) * self.crossing_overlap_mm3


# ----------------------------------------------------------------------------- checks
def part_section(part_kind: str, part: NetDesign | CableDesign) -> Section:
    if part_kind == "net" and isinstance(part, NetDesign):
        return part.strand
    if part_kind == "cable" and isinstance(part, CableDesign):
        return part.section
    raise ProfileError(f"part kind {part_kind!r} does not match {type(part).__name__}; "
                       "use 'net' with a NetDesign or 'cable' with a CableDesign")


def check_part(part_kind: str, part: NetDesign | CableDesign, printer: Printer,
               style: PrintStyle) -> tuple[float, np.ndarray]:
    """Raise a PrintabilityError for a part that cannot be printed; else return its placement.

    Checks passes (>= 1), every bead against the nozzle, layer heights, the part height and
    its footprint on the bed. Returns (angle_rad, centre_xy_mm) of the placement on the bed.
    """
    sec = part_section(part_kind, part)
    where = f"{part_kind} {getattr(part, 'name', '')}".rstrip()
    if style.component != part_kind:
        raise ProfileError(f"print style {style.key!r} is for a {style.component}, not a "
                           f"{part_kind}; set print_style in the design")
    if sec.beads_across < 1 or len(sec.layer_heights_mm) < 1:
        raise PrintabilityError(
            f"{where}: the section has {sec.beads_across} bead(s) x "
            f"{len(sec.layer_heights_mm)} layer(s) = {sec.beads_across * len(sec.layer_heights_mm)}"
            " passes; a printable part needs at least one pass: fix the design's section")
    for k, h in enumerate(sec.layer_heights_mm):
        if not np.isfinite(h) or h <= 0:
            raise PrintabilityError(f"{where}: layer {k} height {h!r} mm must be > 0")
        check_pass(printer, sec.bead_width_mm, h, where=f"{where} layer {k}")
    if sec.thickness_mm > printer.max_height_mm:
        raise PrintabilityError(f"{where}: thickness {sec.thickness_mm:g} mm exceeds the "
                                f"{printer.max_height_mm:g} mm build height of {printer.key}")
    if part_kind == "net":
        check_pass(printer, _border_bead(part)[1], sec.layer_heights_mm[0], where=f"{where} border")
        size = np.array(diamond_net(part.width_mm, part.height_mm, part.mesh_x_mm,
                                    part.mesh_y_mm).size_mm) + part.border_width_mm
    else:
        ring_w = _ring_layout(part)[1]
        check_pass(printer, ring_w, sec.layer_heights_mm[0], where=f"{where} eyelet ring")
        if sec.width_mm >= part.eyelet_outer_mm:
            raise PrintabilityError(
                f"{where}: strip {sec.width_mm:g} mm is not narrower than the eyelet "
                f"({part.eyelet_outer_mm:g} mm outer diameter); widen the eyelet")
        size = np.array([part.length_mm + part.eyelet_outer_mm, part.eyelet_outer_mm])
    return place_on_bed(size, printer, where=where)


def place_on_bed(size_mm: np.ndarray, printer: Printer, *, where: str) -> tuple[float, np.ndarray]:
    """(angle_rad, centre_xy) turning a size_x x size_y part to fit the usable bed, 0 first."""
    usable = np.array([printer.bed_x_mm, printer.bed_y_mm]) - 2 * printer.bed_margin_mm
    for a in np.linspace(0.0, np.pi / 2, N_ORIENTATIONS):
        c, s = abs(np.cos(a)), abs(np.sin(a))
        ext = np.array([size_mm[0] * c + size_mm[1] * s, size_mm[0] * s + size_mm[1] * c])
        if np.all(ext <= usable + 1e-9):
            return float(a), np.array([printer.bed_x_mm, printer.bed_y_mm]) / 2
    raise PrintabilityError(
        f"{where}: part {size_mm[0]:.1f} x {size_mm[1]:.1f} mm does not fit the usable "
        f"{usable[0]:g} x {usable[1]:g} mm of printer {printer.key} (bed {printer.bed_x_mm:g} x "
        f"{printer.bed_y_mm:g} mm less {printer.bed_margin_mm:g} mm margins) in any orientation; "
        "choose a larger printer or a smaller part")


def wall_loops(part_kind: str, part: NetDesign | CableDesign) -> int:
    """Perimeter loops a slicer needs to fill the widest band of the part (2 beads a loop)."""
    if part_kind == "net":
        beads = max(part.strand.beads_across, _border_bead(part)[0])
    else:
        beads = max(part.section.beads_across, _ring_layout(part)[0])
    return max(1, -(-beads // 2))


def _border_bead(net: NetDesign) -> tuple[int, float]:
    """(loops, bead width mm) of the border: whole strand beads across its width."""
    n = max(1, round(net.border_width_mm / net.strand.bead_width_mm))
    return n, net.border_width_mm / n


def _ring_layout(cable: CableDesign) -> tuple[int, float]:
    """(rings, bead width mm) filling the eyelet annulus with beads near the section's."""
    band = (cable.eyelet_outer_mm - cable.eyelet_inner_mm) / 2
    if band <= 0:
        raise PrintabilityError(f"cable {cable.name}: eyelet outer {cable.eyelet_outer_mm:g} mm "
                                f"is not larger than inner {cable.eyelet_inner_mm:g} mm")
    n = max(1, round(band / cable.section.bead_width_mm))
    return n, band / n


def _speeds(material: Material, widths: list[float], heights: list[float]) -> list[float]:
    """Speed per layer (mm/s): the material's speed, capped by its volumetric flow limit."""
    p = material.print
    out = []
    for k, h in enumerate(heights):
        v = p.first_layer_speed_mm_per_s if k == 0 else p.print_speed_mm_per_s
        cap = SPEED_MARGIN * p.max_volumetric_flow_mm3_per_s / (max(widths) * h)
        out.append(min(v, cap))
    return out


# ----------------------------------------------------------------------------- builder
class _Builder:
    def __init__(self, angle: float, centre: np.ndarray, offset: np.ndarray) -> None:
        c, s = np.cos(angle), np.sin(angle)
        self.rot = np.array([[c, -s], [s, c]])
        self.shift = centre - self.rot @ offset
        self.rows: list[tuple[float, float, float, float, float, float, float, int, int]] = []
        self.pos: tuple[float, float, float] | None = None

    def _xy(self, p: np.ndarray) -> np.ndarray:
        return self.rot @ np.asarray(p, dtype=float) + self.shift

    def line(self, p0, p1, z, w, h, v, flow, layer, kind, travel_speed) -> None:
        a, b = self._xy(p0), self._xy(p1)
        start = (float(a[0]), float(a[1]), z)
        if self.pos is None or np.hypot(self.pos[0] - start[0], self.pos[1] - start[1]) > 1e-6 \
                or self.pos[2] != z:
            self.rows.append((*start, 0.0, 0.0, travel_speed, 0.0, layer, TRAVEL))
        self.rows.append((float(b[0]), float(b[1]), z, w, h, v, flow, layer, kind))
        self.pos = (float(b[0]), float(b[1]), z)

    def toolpath(self, layer_z: list[float], part: str) -> Toolpath:
        a = np.array(self.rows, dtype=float)
        return Toolpath(a[:, 0:3].copy(), a[:, 3].copy(), a[:, 4].copy(), a[:, 5].copy(),
                        a[:, 6].copy(), a[:, 7].astype(int), a[:, 8].astype(int),
                        np.array(layer_z), part)


# ----------------------------------------------------------------------------- net
def net_toolpath(net: NetDesign, printer: Printer, style: PrintStyle, material: Material, *,
                 crossing_flow_factor: float | None = None) -> Toolpath:
    """Toolpath of the whole net, one layer per pass (see the module docstring)."""
    angle, centre = check_part("net", net, printer, style)
    f = style.crossing_flow_factor if crossing_flow_factor is None else crossing_flow_factor
    if not 0.0 <= f <= 1.0:
        raise ProfileError(f"crossing_flow_factor {f!r} must lie in 0..1")
    g = diamond_net(net.width_mm, net.height_mm, net.mesh_x_mm, net.mesh_y_mm)
    size = np.array(g.size_mm)
    b = _Builder(angle, centre, size / 2)
    sec = net.strand
    n_loops, wb = _border_bead(net)
    heights = list(sec.layer_heights_mm)
    speeds = _speeds(material, [sec.bead_width_mm, wb], heights)
    travel = printer.travel_speed_mm_per_s
    z = np.cumsum(heights)
    fams = _strands_by_family(g)
    for k, (h, v) in enumerate(zip(heights, speeds, strict=True)):
        zk = float(round(z[k], 6))
        for j in range(n_loops):
            o = (j - (n_loops - 1) / 2) * wb
            corners = [(-o, -o), (size[0] + o, -o), (size[0] + o, size[1] + o),
                       (-o, size[1] + o), (-o, -o)]
            for p0, p1 in itertools.pairwise(corners):
                b.line(p0, p1, zk, wb, h, v, 1.0, k, BORDER, travel)
        order = (1, -1) if k % 2 == 0 else (-1, 1)
        for rank, fam in enumerate(order):
            reduce = rank == 1 and f < 1.0
            for n, s in enumerate(fams[fam]):
                pts = g.nodes_mm[s] if n % 2 == 0 else g.nodes_mm[s[::-1]]
                kind = STRAND_PLUS if fam == 1 else STRAND_MINUS
                for p0, p1, fl in _strand_pieces(pts, sec, g, f if reduce else 1.0):
                    for off in _bead_offsets(sec, p1 - p0):
                        b.line(p0 + off, p1 + off, zk, sec.bead_width_mm, h, v, fl, k, kind,
                               travel)
    return b.toolpath([float(round(x, 6)) for x in z], "net")


def _strands_by_family(g: NetGraph) -> dict[int, list[np.ndarray]]:
    """Strands of each family sorted across the panel (so consecutive strands are neighbours)."""
    out: dict[int, list[np.ndarray]] = {1: [], -1: []}
    a, bb = g.mesh_mm
    for s in g.strands:
        p0, p1 = g.nodes_mm[s[0]], g.nodes_mm[s[-1]]
        fam = 1 if p1[1] > p0[1] else -1
        out[fam].append(s)
    for fam, lst in out.items():
        # intercept of the line y = fam * (b/a) * x + c: sorting by c orders them across
        lst.sort(key=lambda s, fam=fam: g.nodes_mm[s[0], 1] - fam * bb / a * g.nodes_mm[s[0], 0])
    return out


def _crossing_half_span(sec: Section, g: NetGraph) -> float:
    """Half length of a strand lying over a crossing strand of the same width (mm)."""
    return sec.width_mm / 2 / _sin_crossing(g)


def _sin_crossing(g: NetGraph) -> float:
    a, b = g.mesh_mm
    return 2 * a * b / (a * a + b * b)  # sin of the angle between the two families


def _strand_pieces(pts: np.ndarray, sec: Section, g: NetGraph, f: float):
    """Straight pieces (p0, p1, flow) of one strand: one piece unless crossings get less flow."""
    if f >= 1.0 or len(pts) <= 2:
        return [(pts[0], pts[-1], 1.0)]
    d = pts[-1] - pts[0]
    length = float(np.hypot(*d))
    u = d / length
    half = _crossing_half_span(sec, g)
    cuts = [0.0]
    flows = []
    for p in pts[1:-1]:
        t = float(np.dot(p - pts[0], u))
        lo, hi = max(t - half, cuts[-1]), min(t + half, length)
        if lo > cuts[-1]:
            cuts.append(lo)
            flows.append(1.0)
        cuts.append(hi)
        flows.append(f)
    if cuts[-1] < length:
        cuts.append(length)
        flows.append(1.0)
    return [(pts[0] + u * t0, pts[0] + u * t1, fl)
            for t0, t1, fl in zip(cuts[:-1], cuts[1:], flows, strict=True) if t1 > t0]


def _bead_offsets(sec: Section, d: np.ndarray) -> list[np.ndarray]:
    """Perpendicular offsets of the beads side by side in a strand of direction d."""
    n = sec.beads_across
    perp = np.array([-d[1], d[0]]) / np.hypot(*d)
    return [perp * (j - (n - 1) / 2) * sec.bead_width_mm for j in range(n)]


def net_volume_budget(net: NetDesign, style: PrintStyle, *,
                      crossing_flow_factor: float | None = None) -> VolumeBudget:
    """Designed volumes of the net (analytic, rectangular sections)."""
    f = style.crossing_flow_factor if crossing_flow_factor is None else crossing_flow_factor
    g = diamond_net(net.width_mm, net.height_mm, net.mesh_x_mm, net.mesh_y_mm)
    sec = net.strand
    t = sec.thickness_mm
    w = sec.width_mm
    size = np.array(g.size_mm)
    strand_len = sum(float(np.hypot(*(g.nodes_mm[s[-1]] - g.nodes_mm[s[0]]))) for s in g.strands)
    n_cross = sum(len(s) - 2 for s in g.strands) // 2
    border = 2 * (size[0] + size[1]) * net.border_width_mm
    nominal = (strand_len * w + border) * t
    crossing = n_cross * w * w / _sin_crossing(g) * t
    a, b = g.mesh_mm
    diag = np.hypot(a, b)
    junction = 0.0
    for s in g.strands:
        for end in (g.nodes_mm[s[0]], g.nodes_mm[s[-1]]):
            on_side = np.isclose(end[0], 0) or np.isclose(end[0], size[0])
            sin_phi = a / diag if on_side else b / diag  # strand vs the border edge it meets
            junction += net.border_width_mm / 2 / sin_phi * w * t
    return VolumeBudget(nominal, crossing, junction, f, n_cross)


# ----------------------------------------------------------------------------- cable
def cable_toolpath(cable: CableDesign, printer: Printer, style: PrintStyle,
                   material: Material) -> Toolpath:
    """Toolpath of one cable: eyelet rings, then the strip beads, per layer."""
    angle, centre = check_part("cable", cable, printer, style)
    sec = cable.section
    n_rings, wr = _ring_layout(cable)
    ri, ro = cable.eyelet_inner_mm / 2, cable.eyelet_outer_mm / 2
    half = cable.length_mm / 2
    b = _Builder(angle, centre, np.zeros(2))
    heights = list(sec.layer_heights_mm)
    speeds = _speeds(material, [sec.bead_width_mm, wr], heights)
    travel = printer.travel_speed_mm_per_s
    z = np.cumsum(heights)
    offsets = [(j - (sec.beads_across - 1) / 2) * sec.bead_width_mm
               for j in range(sec.beads_across)]
    for k, (h, v) in enumerate(zip(heights, speeds, strict=True)):
        zk = float(round(z[k], 6))
        for cx in (-half, half):
            for j in range(n_rings):
                ring = _circle(np.array([cx, 0.0]), ri + wr * (j + 0.5))
                for p0, p1 in itertools.pairwise(ring):
                    b.line(p0, p1, zk, wr, h, v, 1.0, k, EYELET, travel)
        for j, y in enumerate(offsets):
            x = half - np.sqrt(ro * ro - y * y)
            p0, p1 = np.array([-x, y]), np.array([x, y])
            if j % 2:
                p0, p1 = p1, p0
            b.line(p0, p1, zk, sec.bead_width_mm, h, v, 1.0, k, CABLE_STRIP, travel)
    return b.toolpath([float(round(x, 6)) for x in z], f"cable {cable.name}")


def _circle(c: np.ndarray, r: float) -> np.ndarray:
    n = max(8, int(np.ceil(np.pi / np.arccos(1 - CHORD_TOL_MM / r))))
    t = np.linspace(0.0, 2 * np.pi, n + 1)
    return c + r * np.column_stack([np.cos(t), np.sin(t)])


def cable_volume_budget(cable: CableDesign) -> VolumeBudget:
    """Designed volumes of a cable: two annuli plus the strip between them (mm^3)."""
    sec = cable.section
    ri, ro = cable.eyelet_inner_mm / 2, cable.eyelet_outer_mm / 2
    rings = 2 * np.pi * (ro * ro - ri * ri)
    strip = sum(cable.length_mm - 2 * np.sqrt(ro * ro - y * y)
                for y in ((j - (sec.beads_across - 1) / 2) * sec.bead_width_mm
                          for j in range(sec.beads_across))) * sec.bead_width_mm
    return VolumeBudget((rings + strip) * sec.thickness_mm, 0.0, 0.0, 1.0, 0)
