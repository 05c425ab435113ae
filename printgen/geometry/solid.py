"""Watertight single-body meshes of the printed parts (mm), from 2D outlines (shapely)
extruded to the section thickness (manifold3d), checked after every operation.

Net: every diagonal strand as one straight band of the strand width from border to border
(rigid junctions where the bands cross), plus the border frame of `border_width_mm` centred
on the panel edge, which the border cables thread along - the same layout the direct
G-code lays. Cable: a strip of the section width between two eyelet rings (inner and outer
diameter), eyelet centres `length_mm` apart, centred on the origin.
Needs the `geometry` extra (manifold3d, trimesh, shapely).
"""

from __future__ import annotations

import numpy as np

from printgen.design import CableDesign, NetDesign
from printgen.errors import GeometryError
from printgen.geometry.net import diamond_net

CIRCLE_SEGMENTS = 128  # eyelet polygons: chord error 3e-4 x radius, volume error < 0.05 %


def _libs():
    try:
        import manifold3d
        import shapely
        import trimesh
    except ImportError as exc:  # pragma: no cover - depends on the install
        raise GeometryError(f"meshes need the geometry extra ({exc.name} missing): "
                            "pip install 'printgen[geometry]'") from exc
    return manifold3d, shapely, trimesh


def net_outline(net: NetDesign):
    """Plan view of the net (shapely geometry, mm, origin at the lower-left node)."""
    _, shapely, _ = _libs()
    from shapely.geometry import LineString, box

    _positive(net.strand.width_mm, "net strand width")
    _positive(net.border_width_mm, "net border width")
    g = diamond_net(net.width_mm, net.height_mm, net.mesh_x_mm, net.mesh_y_mm)
    sx, sy = g.size_mm
    bw, w = net.border_width_mm, net.strand.width_mm
    bands = [LineString(g.nodes_mm[[s[0], s[-1]]]).buffer(w / 2, cap_style="flat")
             for s in g.strands]
    frame = box(-bw / 2, -bw / 2, sx + bw / 2, sy + bw / 2).difference(
        box(bw / 2, bw / 2, sx - bw / 2, sy - bw / 2))
    return shapely.unary_union([*bands, frame])


def cable_outline(cable: CableDesign):
    """Plan view of a cable (shapely geometry, mm, centred on the origin, along x)."""
    _, shapely, _ = _libs()
    from shapely.geometry import Point, box

    _positive(cable.length_mm, f"cable {cable.name} length")
    if not cable.eyelet_outer_mm > cable.eyelet_inner_mm > 0:
        raise GeometryError(f"cable {cable.name}: eyelet diameters inner "
                            f"{cable.eyelet_inner_mm:g} mm, outer {cable.eyelet_outer_mm:g} mm; "
                            "need 0 < inner < outer")
    half, w = cable.length_mm / 2, cable.section.width_mm
    if w >= cable.eyelet_outer_mm:
        raise GeometryError(f"cable {cable.name}: strip {w:g} mm is not narrower than the "
                            f"eyelet ({cable.eyelet_outer_mm:g} mm); widen the eyelet")
    if cable.length_mm <= cable.eyelet_outer_mm:
        raise GeometryError(f"cable {cable.name}: length {cable.length_mm:g} mm leaves no strip "
                            f"between eyelets of {cable.eyelet_outer_mm:g} mm")
    q = CIRCLE_SEGMENTS // 4
    ends = (-half, half)
    outline = shapely.unary_union([box(-half, -w / 2, half, w / 2)]
                                  + [Point(x, 0).buffer(cable.eyelet_outer_mm / 2, q)
                                     for x in ends])
    holes = shapely.unary_union([Point(x, 0).buffer(cable.eyelet_inner_mm / 2, q)
                                 for x in ends])
    return outline.difference(holes)


def extrude(outline, thickness_mm: float, name: str):
    """Extrude a shapely (multi)polygon to a watertight trimesh, checking every step."""
    manifold3d, _, trimesh = _libs()
    _positive(thickness_mm, f"{name} thickness")
    polys = list(getattr(outline, "geoms", [outline]))
    if len(polys) != 1:
        raise GeometryError(f"{name}: the outline falls apart into {len(polys)} pieces; a part "
                            "must be one body (check the mesh and border sizes)")
    rings = [np.asarray(polys[0].exterior.coords)[:-1]]
    rings += [np.asarray(r.coords)[:-1] for r in polys[0].interiors]
    section = manifold3d.CrossSection(rings, manifold3d.FillRule.EvenOdd)
    solid = manifold3d.Manifold.extrude(section, thickness_mm)
    if solid.status() != manifold3d.Error.NoError:
        raise GeometryError(f"{name}: extrusion failed ({solid.status()})")
    m = solid.to_mesh()
    mesh = trimesh.Trimesh(np.asarray(m.vert_properties)[:, :3], np.asarray(m.tri_verts),
                           process=False)
    if not mesh.is_watertight:
        raise GeometryError(f"{name}: the mesh is not watertight")
    return mesh


def net_solid(net: NetDesign):
    """The net as one watertight trimesh (mm, z from 0 to the strand thickness)."""
    return extrude(net_outline(net), net.strand.thickness_mm, "net")


def cable_solid(cable: CableDesign):
    """A cable as one watertight trimesh (mm)."""
    return extrude(cable_outline(cable), cable.section.thickness_mm, f"cable {cable.name}")


def _positive(v: float, what: str) -> None:
    if not np.isfinite(v) or v <= 0:
        raise GeometryError(f"{what} = {v!r} mm must be a positive length")
