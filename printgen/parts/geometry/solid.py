"""Watertight single-body meshes of the printed parts (mm), from 2D outlines (shapely)
extruded to the section thickness (manifold3d), checked after every operation.

Net: every diagonal strand of the `NetGraph` as one straight band of the strand width from
border to border (rigid junctions where the bands cross), plus the border frame of
`border_width_mm` centred on the panel edge, which the border cables thread along - the same
layout the direct G-code lays. Optional corner eyelets (`CornerEyelets`) attach the net
corners to the flume anchors: a ring per corner on the outward diagonal, overlapping each
frame arm by half the border width. Cables: `printgen.parts.geometry.cable`.
Needs the `geometry` extra (manifold3d, trimesh, shapely).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from printgen.design.record import CableDesign, Design, NetDesign
from printgen.errors import GeometryError
from printgen.parts.geometry.cable import (
    analytic_cable_volume,
    cable_outline,
    check_positive_mm,
    circle_points,
    circle_scale,
    require_shapely,
)
from printgen.parts.geometry.net import NetGraph, diamond_net

if TYPE_CHECKING:  # pragma: no cover
    import trimesh

__all__ = ["CornerEyelets", "analytic_cable_volume", "analytic_net_area", "analytic_net_volume",
           "cable_outline", "cable_solid", "corner_eyelets_for", "extrude", "net_outline",
           "net_solid"]

AREA_CHECK = 1e-6  # relative: manifold's cross-section area vs shapely's (same polygon)
CORNERS = ((0, 0, -1, -1), (1, 0, 1, -1), (1, 1, 1, 1), (0, 1, -1, 1))  # (at x, at y, dir)


@dataclass(frozen=True)
class CornerEyelets:
    """Eyelet rings at the four net corners (diameters, mm)."""

    inner_mm: float
    outer_mm: float


def corner_eyelets_for(design: Design) -> CornerEyelets:
    """Net corner eyelets that go on the same anchor pins as the cables' eyelets (the cable
    with the largest pin hole sets both diameters)."""
    if not design.cables:
        raise GeometryError("the design has no cables to take the corner eyelet size from; "
                            "pass CornerEyelets(inner_mm, outer_mm) explicitly")
    c = max(design.cables, key=lambda c: c.eyelet_inner_mm)
    return CornerEyelets(c.eyelet_inner_mm, c.eyelet_outer_mm)


def _graph(net: NetDesign) -> NetGraph:
    """The centre-line graph, after checking that the strands and border can be built."""
    check_positive_mm(net.strand.width_mm, "net strand width")
    check_positive_mm(net.strand.thickness_mm, "net strand thickness")
    check_positive_mm(net.border_width_mm, "net border width")
    g = diamond_net(net.width_mm, net.height_mm, net.mesh_x_mm, net.mesh_y_mm)
    a, b = g.mesh_mm
    w, bw = net.strand.width_mm, net.border_width_mm
    spacing = a * b / np.hypot(a, b)  # between neighbouring parallel strands
    if w >= spacing:
        raise GeometryError(f"net strand {w:g} mm wide fills the {spacing:.3g} mm between "
                            f"parallel strands of a {a:g} x {b:g} mm mesh (no openings left); "
                            "use narrower strands or a larger mesh")
    poke = w * max(a, b) / np.hypot(a, b)  # band end across the edge it meets, both sides
    if poke > bw:
        raise GeometryError(f"net strand ends ({w:g} mm wide, {poke:.3g} mm across the edge) "
                            f"stick out of the {bw:g} mm border; border_width_mm must be at "
                            f"least {poke:.3g} mm")
    if bw / 2 + w >= min(a, b) / 2:
        raise GeometryError(f"net border {bw:g} mm wide reaches the first strand crossings "
                            f"{min(a, b) / 2:g} mm from the edge (strand {w:g} mm); use a "
                            f"border narrower than {min(a, b) - 2 * w:.3g} mm or a larger mesh")
    return g


def _eyelet_offset(net: NetDesign, e: CornerEyelets) -> float:
    """Offset (mm, along x and y) of an eyelet centre from the frame's outer corner, such
    that the ring overlaps each frame arm by half the border width; checked."""
    bw, w = net.border_width_mm, net.strand.width_mm
    check_positive_mm(e.inner_mm, "net corner eyelet inner diameter")
    if not (np.isfinite(e.outer_mm) and e.outer_mm > e.inner_mm):
        raise GeometryError(f"net corner eyelets: inner {e.inner_mm:g} mm, outer "
                            f"{e.outer_mm:g} mm; need 0 < inner < outer")
    ro, ri = e.outer_mm / 2, e.inner_mm / 2
    d = (-bw + np.sqrt(8 * ro * ro - bw * bw)) / 4  # sqrt(ro^2 - d^2) = d + bw/2
    hole = ri * circle_scale()
    if d <= hole:
        need = 2 * np.sqrt(((4 * hole + bw) ** 2 + bw * bw) / 8)
        raise GeometryError(f"net corner eyelet ring {e.outer_mm:g} mm outer, {e.inner_mm:g} mm "
                            f"inner is too thin to join a {bw:g} mm border without its hole "
                            f"cutting the frame; use an outer diameter above {need:.3g} mm")
    gap = np.sqrt(2) * (bw / 2 + d) - ro  # ring to the corner node, along the diagonal
    if gap <= w / 2:
        raise GeometryError(f"net corner eyelet ring comes {gap:.3g} mm from the corner node, "
                            f"within the {w:g} mm strand; widen the border or the eyelet hole")
    return float(d)


def net_outline(net: NetDesign, eyelets: CornerEyelets | None = None):
    """Plan view of the net: one shapely Polygon with holes (mm, origin at the lower-left
    node, border frame centred on the panel edge)."""
    g = _graph(net)
    d = None if eyelets is None else _eyelet_offset(net, eyelets)
    shapely = require_shapely()
    from shapely.geometry import LineString, Polygon, box

    sx, sy = g.size_mm
    bw, w = net.border_width_mm, net.strand.width_mm
    bands = [LineString(g.nodes_mm[[s[0], s[-1]]]).buffer(w / 2, cap_style="flat")
             for s in g.strands]
    frame = box(-bw / 2, -bw / 2, sx + bw / 2, sy + bw / 2).difference(
        box(bw / 2, bw / 2, sx - bw / 2, sy - bw / 2))
    pieces, holes = [*bands, frame], []
    if eyelets is not None:
        for cx, cy in _eyelet_centres(g, bw, d):
            pieces.append(Polygon(circle_points(cx, cy, eyelets.outer_mm / 2)))
            holes.append(Polygon(circle_points(cx, cy, eyelets.inner_mm / 2)))
    outline = shapely.unary_union(pieces)
    return outline.difference(shapely.unary_union(holes)) if holes else outline


def _eyelet_centres(g: NetGraph, bw: float, d: float) -> list[tuple[float, float]]:
    sx, sy = g.size_mm
    return [(ix * sx + ux * (bw / 2 + d), iy * sy + uy * (bw / 2 + d))
            for ix, iy, ux, uy in CORNERS]


def analytic_net_area(net: NetDesign, eyelets: CornerEyelets | None = None) -> float:
    """Plan area of the net (mm^2), from the graph alone (no shapely).

    Strand lengths x width, less one rhombus w^2 / sin(theta) per crossing and, per strand
    end, the w x (bw/2) / sin(phi) inside the frame (phi: strand vs the edge it meets), plus
    the frame 2 bw (sx + sy) and the corner rings less their overlap with the frame.
    """
    g = _graph(net)
    a, b = g.mesh_mm
    sx, sy = g.size_mm
    w, bw = net.strand.width_mm, net.border_width_mm
    diag = np.hypot(a, b)
    ends = np.array([[g.nodes_mm[s[0]], g.nodes_mm[s[-1]]] for s in g.strands]).reshape(-1, 2)
    length = float(np.hypot(*(ends[1::2] - ends[::2]).T).sum())
    n_cross = sum(len(s) - 2 for s in g.strands) // 2
    sin_theta = 2 * a * b / diag**2  # between the two strand families
    on_top_bottom = np.isclose(ends[:, 1], 0.0) | np.isclose(ends[:, 1], sy)
    sin_phi = np.where(on_top_bottom, b / diag, a / diag)
    area = (length * w - n_cross * w * w / sin_theta - float(np.sum(bw / 2 / sin_phi)) * w
            + 2 * bw * (sx + sy))
    if eyelets is not None:
        d = _eyelet_offset(net, eyelets)
        ro, ri = eyelets.outer_mm / 2, eyelets.inner_mm / 2
        area += 4 * (np.pi * (ro * ro - ri * ri) - _disc_in_quadrant(ro, d))
    return float(area)


def _disc_in_quadrant(r: float, d: float) -> float:
    """Area of a disc of radius r (centre 0) in {x >= d, y >= d}, for 0 <= d, 2 d^2 < r^2."""
    def f(x: float) -> float:
        return 0.5 * (x * np.sqrt(r * r - x * x) + r * r * np.arcsin(x / r)) - d * x

    return float(f(np.sqrt(r * r - d * d)) - f(d))


def analytic_net_volume(net: NetDesign, eyelets: CornerEyelets | None = None) -> float:
    """Volume of the net (mm^3): plan area x strand thickness."""
    return analytic_net_area(net, eyelets) * net.strand.thickness_mm


def extrude(outline, thickness_mm: float, name: str) -> trimesh.Trimesh:
    """Extrude a shapely Polygon (with holes) to a watertight single-body trimesh (mm)."""
    check_positive_mm(thickness_mm, f"{name} thickness")
    try:
        import manifold3d
        import trimesh
    except ImportError as exc:  # pragma: no cover - depends on the install
        raise GeometryError(f"meshes need the geometry extra ({exc.name} missing): "
                            "pip install 'printgen[geometry]'") from exc
    polys = list(getattr(outline, "geoms", [outline]))
    if len(polys) != 1 or polys[0].is_empty:
        raise GeometryError(f"{name}: the outline falls apart into {len(polys)} pieces; a part "
                            "must be one body (check the mesh and border sizes)")
    rings = [np.asarray(polys[0].exterior.coords)[:-1]]
    rings += [np.asarray(r.coords)[:-1] for r in polys[0].interiors]
    section = manifold3d.CrossSection(rings, manifold3d.FillRule.EvenOdd)
    if abs(section.area() / polys[0].area - 1) > AREA_CHECK:
        raise GeometryError(f"{name}: cross-section area {section.area():.6g} mm^2 differs "
                            f"from the outline's {polys[0].area:.6g} mm^2")
    solid = manifold3d.Manifold.extrude(section, thickness_mm)
    if solid.status() != manifold3d.Error.NoError:
        raise GeometryError(f"{name}: extrusion failed ({solid.status()})")
    if len(solid.decompose()) != 1:
        raise GeometryError(f"{name}: the solid has {len(solid.decompose())} bodies, not one")
    m = solid.to_mesh64()
    mesh = trimesh.Trimesh(np.asarray(m.vert_properties)[:, :3], np.asarray(m.tri_verts),
                           process=False)
    if not (mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0):
        raise GeometryError(f"{name}: the mesh is not a closed, outward-facing surface")
    return mesh


def net_solid(net: NetDesign, eyelets: CornerEyelets | None = None) -> trimesh.Trimesh:
    """The net as one watertight trimesh (mm, z from 0 to the strand thickness)."""
    return extrude(net_outline(net, eyelets), net.strand.thickness_mm, "net")


def cable_solid(cable: CableDesign) -> trimesh.Trimesh:
    """A cable as one watertight trimesh (mm, centred on the origin, along x)."""
    return extrude(cable_outline(cable), cable.section.thickness_mm, f"cable {cable.name}")
