"""Direct toolpath of a border cable (mm, mm/s): per layer, the two eyelets as concentric
rings, then the strip beads side by side from one eyelet to the other.

The strip's beads run on into each eyelet ring up to its hole (the bead corners meet the
hole's edge), so every bead overlaps the ring by more than one bead width and the cable's
force passes through a lap joint, not through the rounded bead ends; over the ring the strip
lays the print style's `crossing_flow_factor` (beads laid over printed beads). Holes are the
design's plus the printer's `hole_compensation_mm`. Long cables are turned on the bed.
"""

from __future__ import annotations

import itertools

import numpy as np

from printgen.errors import PrintabilityError
from printgen.inputs.materials import Material
from printgen.inputs.printers import Printer, PrintStyle
from printgen.parts.gcode.toolpath import (
    CABLE_STRIP,
    EYELET,
    Builder,
    Toolpath,
    VolumeBudget,
    check_part,
    circle,
    ring_layout,
    speeds,
)
from printgen.scaling.record import CableDesign


def cable_toolpath(cable: CableDesign, printer: Printer, style: PrintStyle,
                   material: Material) -> Toolpath:
    """Toolpath of one cable: eyelet rings, then the strip beads into both rings, per layer."""
    angle, centre = check_part("cable", cable, printer, style)
    comp = printer.hole_compensation_mm
    sec = cable.section
    n_rings, wr = ring_layout(cable, comp)
    ri = (cable.eyelet_inner_mm + comp) / 2
    half = cable.length_mm / 2
    b = Builder(angle, centre, np.zeros(2))
    heights = list(sec.layer_heights_mm)
    layer_speeds = speeds(material, [sec.bead_width_mm, wr], heights)
    travel = printer.travel_speed_mm_per_s
    z = np.cumsum(heights)
    for k, (h, v) in enumerate(zip(heights, layer_speeds, strict=True)):
        zk = float(round(z[k], 6))
        for cx in (-half, half):
            for j in range(n_rings):
                ring = circle(np.array([cx, 0.0]), ri + wr * (j + 0.5))
                for p0, p1 in itertools.pairwise(ring):
                    b.line(p0, p1, zk, wr, h, v, 1.0, k, EYELET, travel)
        for j, (y, x_in, x_out) in enumerate(strip_beads(cable, comp)):
            xs = [-x_in, -x_out, x_out, x_in]
            flows = [style.crossing_flow_factor, 1.0, style.crossing_flow_factor]
            if j % 2:
                xs, flows = [-x for x in xs], flows[::-1]
            for x0, x1, fl in zip(xs[:-1], xs[1:], flows, strict=True):
                b.line(np.array([x0, y]), np.array([x1, y]), zk, sec.bead_width_mm, h, v, fl,
                       k, CABLE_STRIP, travel)
    return b.toolpath([float(round(x, 6)) for x in z], f"cable {cable.name}")


def strip_beads(cable: CableDesign, hole_compensation_mm: float = 0.0
                ) -> list[tuple[float, float, float]]:
    """Per strip bead: (y, x where it ends at the hole, x where it enters the ring), mm from
    the cable's centre; checked to overlap the ring by at least one bead width."""
    sec = cable.section
    ro = cable.eyelet_outer_mm / 2
    ri = (cable.eyelet_inner_mm + hole_compensation_mm) / 2
    half, wb = cable.length_mm / 2, sec.bead_width_mm
    out = []
    for j in range(sec.beads_across):
        y = (j - (sec.beads_across - 1) / 2) * wb
        edge = abs(y) + wb / 2  # the bead's edge farther from the axis
        if edge >= ri:
            raise PrintabilityError(f"cable {cable.name}: the strip ({sec.width_mm:g} mm) is "
                                    f"wider than the eyelet hole ({2 * ri:g} mm); widen the "
                                    "hole or narrow the strip")
        x_in = half - np.sqrt(ri * ri - edge * edge)
        x_out = half - np.sqrt(ro * ro - y * y)
        if x_in - x_out < wb:
            raise PrintabilityError(f"cable {cable.name}: the strip overlaps its eyelet ring "
                                    f"by {x_in - x_out:.2f} mm, less than one bead "
                                    f"({wb:g} mm); widen the eyelet ring")
        out.append((float(y), float(x_in), float(x_out)))
    return out


def cable_volume_budget(cable: CableDesign, crossing_flow_factor: float = 1.0,
                        hole_compensation_mm: float = 0.0) -> VolumeBudget:
    """Designed volumes of a cable (mm^3): two annuli plus the strip between them; the strip
    laid over the rings (`junction_overlap`) at `crossing_flow_factor`."""
    sec = cable.section
    ri = (cable.eyelet_inner_mm + hole_compensation_mm) / 2
    ro = cable.eyelet_outer_mm / 2
    rings = 2 * np.pi * (ro * ro - ri * ri)
    beads = strip_beads(cable, hole_compensation_mm)
    strip = sum(2 * x_out for _, _, x_out in beads) * sec.bead_width_mm
    lap = sum(2 * (x_in - x_out) for _, x_in, x_out in beads) * sec.bead_width_mm
    t = sec.thickness_mm
    return VolumeBudget((rings + strip + lap) * t, 0.0, lap * t, 1.0, 0,
                        overlap_flow=crossing_flow_factor)
