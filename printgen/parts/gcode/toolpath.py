"""Toolpaths of the direct G-code (mm, mm/s): the `Toolpath` arrays, the printability checks,
the bed placement and the move builder shared by `netpath` (the net) and `cablepath` (the
cables).

A `Toolpath` is a set of parallel arrays, one row per move, in print order: the end point,
bead width and height, speed and flow fraction. Travel moves have width 0; a travel of kind
COMB runs over beads already printed in the layer and is not retracted by the writer.
`writer` turns it into G-code text; `readback` turns G-code back into a `Toolpath`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import cast

import numpy as np

from printgen.errors import PrintabilityError, ProfileError
from printgen.inputs.materials import Material
from printgen.inputs.printers import Printer, PrintStyle, check_pass
from printgen.parts.geometry.attach import border_beads as border_bead
from printgen.scaling.record import CableDesign, NetDesign, Section

TRAVEL, BORDER, STRAND_PLUS, STRAND_MINUS, CABLE_STRIP, EYELET, COMB = 0, 1, 2, 3, 4, 5, 6
KIND_NAMES = {TRAVEL: "travel", BORDER: "border", STRAND_PLUS: "strand+",
              STRAND_MINUS: "strand-", CABLE_STRIP: "strip", EYELET: "eyelet",
              COMB: "travel over printed beads"}
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
    deposit : what the G-code lays: nominal minus the flow saved over crossings and over
    the junctions (laid at `overlap_flow`)
    """

    nominal_mm3: float
    crossing_overlap_mm3: float
    junction_overlap_mm3: float
    crossing_flow_factor: float
    crossings_per_layer: int
    overlap_flow: float = 1.0

    @property
    def solid_mm3(self) -> float:
        return self.nominal_mm3 - self.crossing_overlap_mm3 - self.junction_overlap_mm3

    @property
    def deposit_mm3(self) -> float:
        return (self.nominal_mm3 - (1.0 - self.crossing_flow_factor) * self.crossing_overlap_mm3
                - (1.0 - self.overlap_flow) * self.junction_overlap_mm3)


# ----------------------------------------------------------------------------- checks
def part_section(part_kind: str, part: NetDesign | CableDesign) -> Section:
    if part_kind == "net" and isinstance(part, NetDesign):
        return part.strand
    if part_kind == "cable" and isinstance(part, CableDesign):
        return part.section
    raise ProfileError(f"part kind {part_kind!r} does not match {type(part).__name__}; "
                       "use 'net' with a NetDesign or 'cable' with a CableDesign")


def check_part(part_kind: str, part: NetDesign | CableDesign, printer: Printer,
               style: PrintStyle, *, reach_mm: float = 0.0) -> tuple[float, np.ndarray]:
    """Raise a PrintabilityError for a part that cannot be printed; else return its placement.

    Checks passes (>= 1), every bead against the nozzle, layer heights, the part height and
    its footprint on the bed (a net reaching `reach_mm` past its corner nodes: its loops and
    corner eyelets). Returns (angle_rad, centre_xy_mm) of the placement on the bed.
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
    if part_kind == "net":  # part_kind names the part's type (mypy cannot follow a string)
        net = cast(NetDesign, part)
        check_pass(printer, border_bead(net)[1], sec.layer_heights_mm[0], where=f"{where} border")
        size = np.array(net.graph().size_mm) \
            + 2 * max(net.border_width_mm / 2, reach_mm)
    else:
        cable = cast(CableDesign, part)
        ring_w = ring_layout(cable, printer.hole_compensation_mm)[1]
        check_pass(printer, ring_w, sec.layer_heights_mm[0], where=f"{where} eyelet ring")
        if sec.width_mm >= cable.eyelet_outer_mm:
            raise PrintabilityError(
                f"{where}: strip {sec.width_mm:g} mm is not narrower than the eyelet "
                f"({cable.eyelet_outer_mm:g} mm outer diameter); widen the eyelet")
        size = np.array([cable.length_mm + cable.eyelet_outer_mm, cable.eyelet_outer_mm])
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
        net = cast(NetDesign, part)
        beads = max(net.strand.beads_across, border_bead(net)[0])
    else:
        cable = cast(CableDesign, part)
        beads = max(cable.section.beads_across, ring_layout(cable)[0])
    return max(1, -(-beads // 2))


def ring_layout(cable: CableDesign, hole_compensation_mm: float = 0.0) -> tuple[int, float]:
    """(rings, bead width mm) filling the eyelet annulus (hole widened by the compensation)
    with beads near the section's."""
    band = (cable.eyelet_outer_mm - cable.eyelet_inner_mm - hole_compensation_mm) / 2
    if band <= 0:
        raise PrintabilityError(f"cable {cable.name}: eyelet outer {cable.eyelet_outer_mm:g} mm "
                                f"is not larger than inner {cable.eyelet_inner_mm:g} mm")
    n = max(1, round(band / cable.section.bead_width_mm))
    return n, band / n


def speeds(material: Material, widths: list[float], heights: list[float]) -> list[float]:
    """Speed per layer (mm/s): the material's speed, capped by its volumetric flow limit."""
    p = material.print
    out = []
    for k, h in enumerate(heights):
        v = p.first_layer_speed_mm_per_s if k == 0 else p.print_speed_mm_per_s
        cap = SPEED_MARGIN * p.max_volumetric_flow_mm3_per_s / (max(widths) * h)
        out.append(min(v, cap))
    return out


# ----------------------------------------------------------------------------- builder
class Builder:
    def __init__(self, angle: float, centre: np.ndarray, offset: np.ndarray) -> None:
        c, s = np.cos(angle), np.sin(angle)
        self.rot = np.array([[c, -s], [s, c]])
        self.shift = centre - self.rot @ offset
        self.rows: list[tuple[float, float, float, float, float, float, float, int, int]] = []
        self.pos: tuple[float, float, float] | None = None

    def _xy(self, p: np.ndarray) -> np.ndarray:
        return self.rot @ np.asarray(p, dtype=float) + self.shift

    def line(self, p0, p1, z, w, h, v, flow, layer, kind, travel_speed) -> None:
        """An extrusion from p0 to p1 (part coordinates), after a travel when not there."""
        a, b = self._xy(p0), self._xy(p1)
        start = (float(a[0]), float(a[1]), z)
        if self.pos is None or np.hypot(self.pos[0] - start[0], self.pos[1] - start[1]) > 1e-6 \
                or self.pos[2] != z:
            self.rows.append((*start, 0.0, 0.0, travel_speed, 0.0, layer, TRAVEL))
        self.rows.append((float(b[0]), float(b[1]), z, w, h, v, flow, layer, kind))
        self.pos = (float(b[0]), float(b[1]), z)

    def part_xy(self) -> np.ndarray:
        """The current position in part coordinates (mm)."""
        assert self.pos is not None
        return self.rot.T @ (np.array(self.pos[:2]) - self.shift)

    def travel(self, pts: np.ndarray, z: float, layer: int, speed: float, kind: int) -> None:
        """Travel through the points `pts` ((k, 2), part coordinates) at height z."""
        for p in pts:
            q = self._xy(p)
            self.rows.append((float(q[0]), float(q[1]), z, 0.0, 0.0, speed, 0.0, layer, kind))
            self.pos = (float(q[0]), float(q[1]), z)

    def toolpath(self, layer_z: list[float], part: str) -> Toolpath:
        a = np.array(self.rows, dtype=float)
        return Toolpath(a[:, 0:3].copy(), a[:, 3].copy(), a[:, 4].copy(), a[:, 5].copy(),
                        a[:, 6].copy(), a[:, 7].astype(int), a[:, 8].astype(int),
                        np.array(layer_z), part)


def circle(c: np.ndarray, r: float) -> np.ndarray:
    n = max(8, int(np.ceil(np.pi / np.arccos(1 - CHORD_TOL_MM / r))))
    t = np.linspace(0.0, 2 * np.pi, n + 1)
    return c + r * np.column_stack([np.cos(t), np.sin(t)])
