"""Watertight single-body meshes of the printed parts (mm), from 2D outlines (shapely)
extruded to the section thickness (manifold3d), checked after every operation.

Net: every strand of the `NetGraph` (the diamond's diagonals, the square's strands up and
across) as one straight band of the strand width from
border to border (rigid junctions where the bands cross) - or, with the design's wave, a band
along the strand's waved centre line (`printgen.parts.geometry.wave`) - plus the border frame of
`border_width_mm` centred on the panel edge, which the border cables thread along - the same
layout the direct G-code lays. With an `Attachment` (`printgen.parts.geometry.attach`) a
loop is centred on every edge node, through which the cable strip threads, and an eyelet on
every corner node, which goes on the flume's anchor pin. Cables:
`printgen.parts.geometry.cable`.
Needs the `geometry` extra (manifold3d, trimesh, shapely).
"""

from __future__ import annotations

import functools
from typing import TYPE_CHECKING

import numpy as np

from printgen.barrier.graph import NetGraph
from printgen.errors import GeometryError
from printgen.parts.geometry.attach import Attachment, Hole, attachment_for, holes
from printgen.parts.geometry.cable import (
    analytic_cable_volume,
    cable_outline,
    check_positive_mm,
    circle_points,
    require_shapely,
)
from printgen.parts.geometry.lattice import (
    crossing_sin,
    end_poke,
    end_sin,
    first_inner_node_mm,
    parallel_spacing,
    strand_ends,
)
from printgen.parts.geometry.wave import check_inside, check_net_wave, waved_areas, waved_strands
from printgen.scaling.record import CableDesign, NetDesign

if TYPE_CHECKING:  # pragma: no cover
    import trimesh

__all__ = ["Attachment", "analytic_cable_volume", "analytic_net_area", "analytic_net_volume",
           "attachment_for", "cable_outline", "cable_solid", "extrude", "net_outline",
           "net_solid"]

AREA_CHECK = 1e-6  # relative: manifold's cross-section area vs shapely's (same polygon)
QUAD_RINGS, QUAD_ANGLES = 200, 720  # polar grid of the in-ring area integral (~1e-3 of it)


def _graph(net: NetDesign) -> NetGraph:
    """The centre-line graph, after checking that the strands and border can be built."""
    check_positive_mm(net.strand.width_mm, "net strand width")
    check_positive_mm(net.strand.thickness_mm, "net strand thickness")
    check_positive_mm(net.border_width_mm, "net border width")
    check_net_wave(net)
    g = net.graph()
    a, b = g.mesh_mm
    w, bw = net.strand.width_mm, net.border_width_mm
    spacing = parallel_spacing(g)  # between neighbouring parallel strands
    if w >= spacing:
        raise GeometryError(f"net strand {w:g} mm wide fills the {spacing:.3g} mm between "
                            f"parallel strands of a {a:g} x {b:g} mm mesh (no openings left); "
                            "use narrower strands or a larger mesh")
    poke = end_poke(g, w)  # band end across the edge it meets, both sides
    if poke > bw:
        raise GeometryError(f"net strand ends ({w:g} mm wide, {poke:.3g} mm across the edge) "
                            f"stick out of the {bw:g} mm border; border_width_mm must be at "
                            f"least {poke:.3g} mm")
    first = first_inner_node_mm(g)
    if bw / 2 + w >= first:
        raise GeometryError(f"net border {bw:g} mm wide reaches the first strand crossings "
                            f"{first:g} mm from the edge (strand {w:g} mm); use a "
                            f"border narrower than {2 * (first - w):.3g} mm or a larger mesh")
    check_inside(net, g)
    return g


def net_outline(net: NetDesign, attachment: Attachment | None = None):
    """Plan view of the net: one shapely Polygon with holes (mm, origin at the lower-left
    node, border frame centred on the panel edge), with the loops and corner eyelets of
    `attachment` when given."""
    g = _graph(net)
    hs = [] if attachment is None else holes(net, g, attachment)
    shapely = require_shapely()
    from shapely.geometry import Polygon

    pieces = [*_strand_bands(net, g), _frame(net, g)]
    pieces += [Polygon(circle_points(h.centre_mm[0], h.centre_mm[1], h.outer_r_mm)) for h in hs]
    outline = shapely.unary_union(pieces)
    if not hs:
        return outline
    return outline.difference(shapely.unary_union(
        [Polygon(circle_points(h.centre_mm[0], h.centre_mm[1], h.hole_r_mm)) for h in hs]))


def _strand_bands(net: NetDesign, g: NetGraph) -> list:
    from shapely.geometry import LineString

    if net.wave is not None:
        lines = waved_strands(g, net.wave)
        return [LineString(ws.polyline(0.0, ws.length)).buffer(net.strand.width_mm / 2,
                                                               cap_style="flat")
                for ws in lines]
    return [LineString(g.nodes_mm[[s[0], s[-1]]]).buffer(net.strand.width_mm / 2,
                                                          cap_style="flat")
            for s in g.strands]


def _frame(net: NetDesign, g: NetGraph):
    from shapely.geometry import box

    sx, sy = g.size_mm
    bw = net.border_width_mm
    return box(-bw / 2, -bw / 2, sx + bw / 2, sy + bw / 2).difference(
        box(bw / 2, bw / 2, sx - bw / 2, sy - bw / 2))


def analytic_net_area(net: NetDesign, attachment: Attachment | None = None) -> float:
    """Plan area of the net (mm^2), from the graph alone (no shapely).

    Strand lengths x width, less one rhombus w^2 / sin(theta) per crossing (theta between
    the crossing strands: `lattice.crossing_sin`) and, per strand end, the w x (bw/2) /
    sin(phi) inside the frame (phi: strand vs the edge it meets, `lattice.end_sin`), plus
    the frame 2 bw (sx + sy). A waved net: the same terms along the waved centre lines
    (`wave.waved_areas`: arc lengths in closed form, the tangents' angles at the crossings,
    the ends' arcs inside the frame). Each ring adds its disc less the frame and strands
    already inside it (a polar-grid integral of numpy point tests) and removes its hole.
    """
    g = _graph(net)
    sx, sy = g.size_mm
    w, bw = net.strand.width_mm, net.border_width_mm
    if net.wave is not None:
        wa = waved_areas(net, g)
        area = wa.strands - wa.crossings - wa.ends + 2 * bw * (sx + sy)
    else:
        ends = strand_ends(g).reshape(-1, 2)
        length = float(np.hypot(*(ends[1::2] - ends[::2]).T).sum())
        n_cross = sum(len(s) - 2 for s in g.strands) // 2
        area = (length * w - n_cross * w * w / crossing_sin(g)
                - float(np.sum(bw / 2 / end_sin(g))) * w + 2 * bw * (sx + sy))
    if attachment is not None:
        for h in holes(net, g, attachment):
            area += np.pi * (h.outer_r_mm**2 - h.hole_r_mm**2) - _base_in_disc(net, g, h)
    return float(area)


def _base_in_disc(net: NetDesign, g: NetGraph, h: Hole) -> float:
    """Area (mm^2) of frame and strands within a ring's outer radius (hole included)."""
    (ox, oy), cell = _polar_grid(h.outer_r_mm)
    x, y = h.centre_mm[0] + ox, h.centre_mm[1] + oy
    sx, sy = g.size_mm
    half = net.border_width_mm / 2
    outer = (x >= -half) & (x <= sx + half) & (y >= -half) & (y <= sy + half)
    inner = (x > half) & (x < sx - half) & (y > half) & (y < sy - half)
    inside = outer & ~inner
    sway = 0.0 if net.wave is None else net.wave.amplitude_mm  # a wave strays this off its chord
    waved = {} if net.wave is None else {
        (int(s[0]), int(s[-1])): ws for s, ws in zip(g.strands, waved_strands(g, net.wave),
                                                   strict=True)}
    for s in _strands_near(g, h.centre_mm, h.outer_r_mm + net.strand.width_mm + sway):
        p0, p1 = g.nodes_mm[s[0]], g.nodes_mm[s[-1]]
        d = p1 - p0
        length = float(np.hypot(*d))
        u = d / length
        rx, ry = x - p0[0], y - p0[1]
        along = rx * u[0] + ry * u[1]
        across = np.abs(rx * -u[1] + ry * u[0])
        if net.wave is not None:
            # off the waved centre line: its offset along the normal, to first order in the
            # distance (the wave is straight at the junction a ring sits on: no curvature)
            wy, slope = waved[int(s[0]), int(s[-1])].shape(np.clip(along, 0.0, length))
            across = np.abs(rx * -u[1] + ry * u[0] - wy) / np.sqrt(1 + slope * slope)
        inside |= (along >= 0) & (along <= length) & (across <= net.strand.width_mm / 2)
    return float(np.sum(cell * inside))


@functools.lru_cache(maxsize=8)
def _polar_grid(radius_mm: float) -> tuple[np.ndarray, np.ndarray]:
    """Points of the in-ring area integral about the origin (x and y, each QUAD_RINGS x
    QUAD_ANGLES, mm) and the area of each one's cell (mm^2): the same for every ring of one
    radius."""
    r = radius_mm * (np.arange(QUAD_RINGS) + 0.5) / QUAD_RINGS
    t = (np.arange(QUAD_ANGLES) + 0.5) * (2 * np.pi / QUAD_ANGLES)
    rr, tt = np.meshgrid(r, t, indexing="ij")
    offsets = np.stack([rr * np.cos(tt), rr * np.sin(tt)])
    cell = radius_mm / QUAD_RINGS * (2 * np.pi / QUAD_ANGLES) * rr
    offsets.flags.writeable = cell.flags.writeable = False  # shared by the cache
    return offsets, cell


def _strands_near(g: NetGraph, centre_mm: np.ndarray, reach_mm: float) -> list:
    """The strands whose centre line passes within `reach_mm` of `centre_mm`. The others
    cannot hold a point of the disc (reach: its radius plus the strand width, which covers
    the half width the point test uses with a margin), so leaving them out of the point tests
    changes no point and no bit of the integral."""
    ends = np.array([[g.nodes_mm[s[0]], g.nodes_mm[s[-1]]] for s in g.strands])
    d = ends[:, 1] - ends[:, 0]
    t = np.clip(np.einsum("ij,ij->i", centre_mm - ends[:, 0], d)
                / np.einsum("ij,ij->i", d, d), 0.0, 1.0)
    gap = np.hypot(*(ends[:, 0] + t[:, None] * d - centre_mm).T)
    return [s for s, near in zip(g.strands, gap <= reach_mm, strict=True) if near]


def analytic_net_volume(net: NetDesign, attachment: Attachment | None = None) -> float:
    """Volume of the net (mm^3): plan area x strand thickness."""
    return analytic_net_area(net, attachment) * net.strand.thickness_mm


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


def net_solid(net: NetDesign, attachment: Attachment | None = None) -> trimesh.Trimesh:
    """The net as one watertight trimesh (mm, z from 0 to the strand thickness)."""
    return extrude(net_outline(net, attachment), net.strand.thickness_mm, "net")


def cable_solid(cable: CableDesign, hole_compensation_mm: float = 0.0) -> trimesh.Trimesh:
    """A cable as one watertight trimesh (mm, centred on the origin, along x)."""
    return extrude(cable_outline(cable, hole_compensation_mm), cable.section.thickness_mm,
                   f"cable {cable.name}")
