"""Direct toolpath of the waved-strand coupon (`printgen.parts.geometry.wavecoupon`, mm,
mm/s): per layer, each grip tab as beads along the load side by side (a serpentine across the
tab), then each strand's beads along its waved centre line, offset along the wave's normal,
as fine polylines (`wave.WavedStrand.polyline`: within the wave's chord tolerance).

The strand beads run on into both tabs by the coupon's lap (`WavedCoupon.lap_mm`), laid there
over the tab's beads at the print style's `crossing_flow_factor`, as a net's beads over its
crossings: the strand's force passes into the tab through a lap joint, not through its bead
ends. The tab beads lie along the load (the grip pulls along them); their width is the tab's
width over a whole number of beads near the strand's bead width.
"""

from __future__ import annotations

import numpy as np

from printgen.inputs.materials import Material
from printgen.inputs.printers import Printer, PrintStyle, check_pass
from printgen.parts.gcode.toolpath import (
    BORDER,
    STRAND_PLUS,
    Builder,
    Toolpath,
    VolumeBudget,
    place_on_bed,
    speeds,
)
from printgen.parts.geometry.wavecoupon import WavedCoupon


def tab_beads(c: WavedCoupon) -> tuple[int, float]:
    """(beads, bead width mm) across a tab: whole beads near the strand's bead width."""
    n = max(1, round(c.width_mm / c.section.bead_width_mm))
    return n, c.width_mm / n


def coupon_toolpath(c: WavedCoupon, printer: Printer, style: PrintStyle,
                    material: Material) -> Toolpath:
    """Toolpath of the waved coupon: the tabs, then the strands' beads, per layer."""
    sec = c.section
    nb, wt = tab_beads(c)
    where = f"waved coupon {c.name}"
    for k, h in enumerate(sec.layer_heights_mm):
        check_pass(printer, sec.bead_width_mm, h, where=f"{where} layer {k}")
        check_pass(printer, wt, h, where=f"{where} tab layer {k}")
    angle, centre = place_on_bed(np.array([c.length_mm, c.width_mm]), printer, where=where)
    b = Builder(angle, centre, np.array([c.chord_mm / 2, 0.0]))
    heights = list(sec.layer_heights_mm)
    layer_speeds = speeds(material, [sec.bead_width_mm, wt], heights)
    travel = printer.travel_speed_mm_per_s
    z = np.cumsum(heights)
    lines = _strand_lines(c)
    for k, (h, v) in enumerate(zip(heights, layer_speeds, strict=True)):
        zk = float(round(z[k], 6))
        for x0, x1 in ((-c.tab_mm, 0.0), (c.chord_mm, c.length_mm - c.tab_mm)):
            for i in range(nb):
                y = -c.width_mm / 2 + (i + 0.5) * wt
                xs = (x0, x1) if i % 2 == 0 else (x1, x0)
                b.line(np.array([xs[0], y]), np.array([xs[1], y]), zk, wt, h, v, 1.0, k,
                       BORDER, travel)
        for i, line in enumerate(lines):
            pts = line if (i + k) % 2 == 0 else line[::-1]
            for p0, p1, lap in zip(pts[:-1], pts[1:], _in_tabs(pts, c.chord_mm), strict=True):
                b.line(p0, p1, zk, sec.bead_width_mm, h, v,
                       style.crossing_flow_factor if lap else 1.0, k, STRAND_PLUS, travel)
    return b.toolpath([float(round(x, 6)) for x in z], f"waved coupon {c.name}")


def _strand_lines(c: WavedCoupon) -> list[np.ndarray]:
    """The polyline of every strand bead (strand by strand, bead by bead across it), each
    from inside the left tab to inside the right one, with a point on each tab edge."""
    sec, lap = c.section, c.lap_mm()
    out = []
    for j in range(c.strands):
        ws = c.centre_line(j)
        for i in range(sec.beads_across):
            off = (i - (sec.beads_across - 1) / 2) * sec.bead_width_mm
            out.append(_split_at_edges(ws.polyline(-lap, c.chord_mm + lap, off), c.chord_mm))
    return out


def _in_tabs(line: np.ndarray, chord_mm: float) -> np.ndarray:
    """Per move of polyline `line` (split at the tab edges: `_split_at_edges`), whether it
    lies in a tab (its midpoint outside the gauge, 0 to chord_mm)."""
    mid = (line[1:, 0] + line[:-1, 0]) / 2
    return (mid < 0.0) | (mid > chord_mm)


def _split_at_edges(p: np.ndarray, chord_mm: float) -> np.ndarray:
    """The polyline `p` with a point inserted where it crosses x = 0 and x = chord_mm (the tab
    edges), so each move lies wholly in the gauge or in a tab."""
    out = [p[0]]
    for a, b in zip(p[:-1], p[1:], strict=True):
        for edge in (0.0, chord_mm):
            if (a[0] - edge) * (b[0] - edge) < 0:
                f = (edge - a[0]) / (b[0] - a[0])
                out.append(a + f * (b - a))
        out.append(b)
    return np.array(out)


def coupon_volume_budget(c: WavedCoupon, crossing_flow_factor: float) -> VolumeBudget:
    """Designed volumes of the coupon (mm^3): the tabs and every strand bead over its whole
    polyline (`nominal`), the beads' laps inside the tabs (`junction_overlap`, laid at
    `crossing_flow_factor`)."""
    sec = c.section
    t = sec.thickness_mm
    tabs = 2 * c.tab_mm * c.width_mm
    gauge = lap = 0.0
    for line in _strand_lines(c):
        seg = np.hypot(*np.diff(line, axis=0).T)
        inside = _in_tabs(line, c.chord_mm)
        gauge += float(seg[~inside].sum()) * sec.bead_width_mm
        lap += float(seg[inside].sum()) * sec.bead_width_mm
    return VolumeBudget((tabs + gauge + lap) * t, 0.0, lap * t, 1.0, 0,
                        overlap_flow=crossing_flow_factor)
