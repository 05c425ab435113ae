"""How the net meets the cables and the flume anchors (plan view, mm).

The solver scene (`printgen.scene.scenes`) slides each border cable through the net's edge
nodes between four corner anchors. The printed net does the same: a **loop** (a hole in a
ring) is centred on every edge node, and an **eyelet** on every corner node; the cable
strip threads through the loops of its side and the cable's own eyelets go on the flume's
anchor pins together with the net's corner eyelets. So the net's corner nodes are the
anchors, and a cable is exactly as long (eyelet centre to eyelet centre) as the net's side.

Loop hole: the strip's section (w x t) fits in any orientation with `clearance_mm` each side,
D = sqrt(w^2 + t^2) + 2 c. Each border bead detours around the hole on its own side of the
edge, so the ring is half the border wide on each side and the frame's section carries on
around the loop. Corner eyelets: the cables' pin hole, with `CORNER_EXTRA_RINGS` full
bead rings inside the border's detour. Holes are made larger by the printer's
`hole_compensation_mm` (FDM holes print small); the nominal sizes are what a caliper should
read after printing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from printgen.barrier.graph import NetGraph
from printgen.errors import GeometryError
from printgen.scaling.record import Design, NetDesign

DEFAULT_CLEARANCE_MM = 0.3  # at least 0.3 mm each side of the strip in a loop
CORNER_EXTRA_RINGS = 1  # full bead rings around the pin hole, inside the border's detour
MIN_WEB_FRACTION = 1.0  # material between two holes: at least one ring width


@dataclass(frozen=True)
class Attachment:
    """Sizes of the net's loops and corner eyelets (mm; hole sizes nominal, as printed).

    strip_width_mm, strip_thickness_mm : the cable strip that threads the loops
    clearance_mm : gap each side of the strip in a loop, in any orientation of the strip
    pin_hole_mm : corner eyelet hole, the same as the cables' eyelet hole (one anchor pin)
    hole_compensation_mm : added to every hole diameter in the mesh and the G-code
    """

    strip_width_mm: float
    strip_thickness_mm: float
    clearance_mm: float
    pin_hole_mm: float
    hole_compensation_mm: float = 0.0

    @property
    def loop_hole_mm(self) -> float:
        """Nominal loop hole diameter: the strip's diagonal plus the clearance both sides."""
        return float(np.hypot(self.strip_width_mm, self.strip_thickness_mm)
                     + 2 * self.clearance_mm)

    def strip_clearance_mm(self, hole_mm: float | None = None) -> float:
        """Smallest gap between the strip and a loop of `hole_mm` (nominal by default)."""
        d = self.loop_hole_mm if hole_mm is None else hole_mm
        return float((d - np.hypot(self.strip_width_mm, self.strip_thickness_mm)) / 2)


@dataclass(frozen=True)
class Hole:
    """One loop or corner eyelet: centre (mm), modelled hole radius and ring outer radius."""

    node: int
    centre_mm: np.ndarray
    hole_r_mm: float
    outer_r_mm: float
    corner: bool


def attachment_for(design: Design, *, hole_compensation_mm: float = 0.0,
                   clearance_mm: float = DEFAULT_CLEARANCE_MM) -> Attachment:
    """The attachment sized from the design's cables (the largest strip and pin hole)."""
    if not design.cables:
        raise GeometryError("the design has no border cables, so the net needs no loops; "
                            "build the net without an Attachment")
    w = max(c.section.width_mm for c in design.cables)
    t = max(c.section.thickness_mm for c in design.cables)
    pin = max(c.eyelet_inner_mm for c in design.cables)
    att = Attachment(w, t, clearance_mm, pin, hole_compensation_mm)
    check_attachment(att)
    return att


def check_attachment(att: Attachment) -> None:
    """GeometryError for a negative clearance, a compensation outside 0..1 mm, bad sizes."""
    if not (np.isfinite(att.clearance_mm) and att.clearance_mm >= 0):
        raise GeometryError(f"loop clearance {att.clearance_mm!r} mm must be >= 0")
    if not (np.isfinite(att.hole_compensation_mm) and 0 <= att.hole_compensation_mm < 1.0):
        raise GeometryError(f"hole compensation {att.hole_compensation_mm!r} mm must lie in "
                            "0..1 mm; fix hole_compensation_mm in the printer profile")
    for label, v in (("strip width", att.strip_width_mm),
                     ("strip thickness", att.strip_thickness_mm), ("pin hole", att.pin_hole_mm)):
        if not (np.isfinite(v) and v > 0):
            raise GeometryError(f"attachment {label} = {v!r} mm must be a positive length")


def border_beads(net: NetDesign) -> tuple[int, float]:
    """(beads, bead width mm) of the border frame: whole strand beads across its width."""
    n = max(1, round(net.border_width_mm / net.strand.bead_width_mm))
    return n, net.border_width_mm / n


def corner_nodes(g: NetGraph) -> np.ndarray:
    """(4,) node indices of the corners: lower-left, lower-right, upper-right, upper-left."""
    sx, sy = g.size_mm
    want = np.array([[0.0, 0.0], [sx, 0.0], [sx, sy], [0.0, sy]])
    return np.array([int(np.argmin(np.hypot(*(g.nodes_mm - p).T))) for p in want])


def holes(net: NetDesign, g: NetGraph, att: Attachment) -> list[Hole]:
    """Every loop and corner eyelet of the net, in border order; checked (see `check_holes`)."""
    check_attachment(att)
    n, wb = border_beads(net)
    if n % 2:
        raise GeometryError(f"net border of {n} bead(s) cannot split around the loops; "
                            "use an even number of border beads (border_width_mm = 2 x bead)")
    half = net.border_width_mm / 2
    corners = set(corner_nodes(g).tolist())
    out = []
    for node in g.border:
        corner = int(node) in corners
        hole = (att.pin_hole_mm if corner else att.loop_hole_mm) + att.hole_compensation_mm
        ring = half + (CORNER_EXTRA_RINGS * wb if corner else 0.0)
        out.append(Hole(int(node), g.nodes_mm[node].copy(), hole / 2, hole / 2 + ring, corner))
    check_holes(net, g, out)
    return out


def check_holes(net: NetDesign, g: NetGraph, hs: list[Hole]) -> None:
    """GeometryError when two holes come closer than one ring width, or a hole swallows the
    first strand node inside the net."""
    web = MIN_WEB_FRACTION * net.border_width_mm / 2
    c = np.array([h.centre_mm for h in hs])
    r = np.array([h.hole_r_mm for h in hs])
    d = np.hypot(*(c[:, None, :] - c[None, :, :]).transpose(2, 0, 1))
    gap = d - r[:, None] - r[None, :]
    np.fill_diagonal(gap, np.inf)
    i, j = np.unravel_index(int(np.argmin(gap)), gap.shape)
    if gap[i, j] < web:
        raise GeometryError(
            f"net loops/eyelets at ({c[i, 0]:.1f}, {c[i, 1]:.1f}) and ({c[j, 0]:.1f}, "
            f"{c[j, 1]:.1f}) mm leave {gap[i, j]:.2f} mm of material between their holes, "
            f"less than {web:.2f} mm; use a larger mesh, a thinner cable or smaller anchor pins")
    inner = np.setdiff1d(np.arange(len(g.nodes_mm)), g.border)
    if len(inner):
        dn = np.hypot(*(g.nodes_mm[inner][:, None, :] - c[None, :, :]).transpose(2, 0, 1))
        k = int(np.argmin(np.min(dn - np.array([h.outer_r_mm for h in hs])[None, :], axis=0)))
        if np.min(dn[:, k]) <= hs[k].outer_r_mm + net.strand.width_mm:
            raise GeometryError(f"the ring at ({c[k, 0]:.1f}, {c[k, 1]:.1f}) mm "
                                f"({2 * hs[k].outer_r_mm:.2f} mm across) reaches the first "
                                "strand crossing; use a larger mesh or smaller holes")
