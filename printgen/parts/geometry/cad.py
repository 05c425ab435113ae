"""STEP export through CadQuery's OCP kernel (the optional `cad` extra, imported only when
asked for): the part's plan-view outline (`solid.net_outline` / `cable.cable_outline`) as
planar faces swept into prisms (glued into one solid), in mm. The input is checked before OCP
is imported or anything is written."""

from __future__ import annotations

import itertools
import tempfile
from pathlib import Path

import numpy as np

from printgen.errors import GeometryError
from printgen.outputs import write_bytes
from printgen.parts.geometry.cable import check_positive_mm

INSTALL_HINT = "pip install 'printgen[cad]'"  # quoted: zsh globs brackets
STEP_SIMPLIFY_MM = 0.005  # outline vertices dropped within 5 um (circles: 128 -> ~20 sides)
STEP_VOLUME_TOL = 1e-3  # the prism's volume vs the mesh outline's area x thickness
STEP_HOLES_PER_FACE = 30  # OCCT's STEP writer takes time ~ (wires per face)^2: the plan face
#                           is cut into strips of about this many holes (1:40 net: 12 -> 5 s)


def _cadquery():
    try:
        import cadquery
    except ImportError as exc:
        raise GeometryError(f"STEP output needs CadQuery, which is not installed: "
                            f"{INSTALL_HINT} (or leave out --step)") from exc
    return cadquery


def _single_polygon(outline):
    polys = list(getattr(outline, "geoms", [outline]))
    if len(polys) != 1 or polys[0].is_empty:
        raise GeometryError(f"outline has {len(polys)} pieces; a STEP part must be one body")
    return polys[0]


def step_bytes(outline, thickness_mm: float) -> bytes:
    """STEP text of a shapely polygon (with holes) extruded by `thickness_mm` (mm).

    Planar faces (outer wire plus one wire per hole) swept into prisms: no boolean per hole.
    A face with many holes is cut into strips first (STEP_HOLES_PER_FACE) whose prisms are
    glued back into one solid. Circles are thinned to STEP_SIMPLIFY_MM (fewer faces to
    write); the solid's volume is checked against the mesh outline's area x thickness.
    """
    check_positive_mm(thickness_mm, "STEP part thickness")
    full = _single_polygon(outline)
    from shapely.geometry.polygon import orient

    # exterior counter-clockwise, holes clockwise; circles thinned to STEP_SIMPLIFY_MM
    poly = orient(full.simplify(STEP_SIMPLIFY_MM, preserve_topology=True), sign=1.0)
    _cadquery()  # the install hint when CadQuery (and its OCP kernel) is missing
    solid = _glued([_prism(p, thickness_mm) for p in _strips(poly, STEP_HOLES_PER_FACE)])
    volume = _volume_mm3(solid)
    expected = full.area * thickness_mm
    if not poly.is_valid or abs(volume / expected - 1) > STEP_VOLUME_TOL:
        raise GeometryError(f"STEP: solid volume {volume:.6g} mm^3 differs from the outline's "
                            f"{expected:.6g} mm^3")
    if _count(solid, "SOLID") != 1:
        raise GeometryError(f"STEP: the glued strips make {_count(solid, 'SOLID')} solids, "
                            "not one")
    return _write(solid)


def _strips(poly, holes_per_face: int) -> list:
    """`poly` cut by vertical lines into pieces of about `holes_per_face` holes each (a strip
    may fall apart into several pieces). Each line lies in the widest gap between the
    outline's vertex x coordinates near its even spacing, so that it meets no vertex."""
    from shapely.geometry import box
    from shapely.geometry.polygon import orient

    k = -(-len(poly.interiors) // holes_per_face)
    if k <= 1:
        return [poly]
    x0, y0, x1, y1 = poly.bounds
    xs = np.unique(np.concatenate([np.asarray(r.coords)[:, 0]
                                   for r in [poly.exterior, *poly.interiors]]))
    half = (x1 - x0) / (4 * k)  # search window about each evenly spaced line
    cuts = [x0 - 1.0]
    for t in x0 + (x1 - x0) * np.arange(1, k) / k:
        gaps = np.concatenate([[t - half], xs[(xs > t - half) & (xs < t + half)], [t + half]])
        j = int(np.argmax(np.diff(gaps)))
        cuts.append((gaps[j] + gaps[j + 1]) / 2)
    cuts.append(x1 + 1.0)
    pieces = []
    for a, b in itertools.pairwise(cuts):
        part = poly.intersection(box(a, y0 - 1.0, b, y1 + 1.0))
        pieces += [orient(p, sign=1.0) for p in getattr(part, "geoms", [part])
                   if p.geom_type == "Polygon" and not p.is_empty]
    return pieces


def _prism(poly, thickness_mm: float):
    """One planar face (outer wire plus one wire per hole) swept into a prism."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism
    from OCP.gp import gp_Vec

    maker = BRepBuilderAPI_MakeFace(_wire(poly.exterior), True)
    for hole in poly.interiors:
        maker.Add(_wire(hole))
    if not maker.IsDone():
        raise GeometryError("STEP: the outline does not make a planar face")
    return BRepPrimAPI_MakePrism(maker.Face(), gp_Vec(0.0, 0.0, thickness_mm)).Shape()


def _glued(solids: list):
    """The prisms fused into one solid; they only touch on the cut planes, which OCCT's glue
    option fuses without intersecting every face pair. One prism is returned as it is."""
    if len(solids) == 1:
        return solids[0]
    from OCP.BOPAlgo import BOPAlgo_GlueShift
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Fuse
    from OCP.TopTools import TopTools_ListOfShape

    args, tools = TopTools_ListOfShape(), TopTools_ListOfShape()
    args.Append(solids[0])
    for s in solids[1:]:
        tools.Append(s)
    fuse = BRepAlgoAPI_Fuse()
    fuse.SetArguments(args)
    fuse.SetTools(tools)
    fuse.SetGlue(BOPAlgo_GlueShift)
    fuse.Build()
    if not fuse.IsDone():
        raise GeometryError("STEP: the strips of the outline could not be fused")
    return fuse.Shape()


def _count(shape, kind: str) -> int:
    from OCP.TopAbs import TopAbs_ShapeEnum
    from OCP.TopExp import TopExp_Explorer

    explorer, n = TopExp_Explorer(shape, getattr(TopAbs_ShapeEnum, f"TopAbs_{kind}")), 0
    while explorer.More():
        n += 1
        explorer.Next()
    return n


def _wire(ring):
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakePolygon
    from OCP.gp import gp_Pnt

    mp = BRepBuilderAPI_MakePolygon()
    for x, y in np.asarray(ring.coords)[:-1]:
        mp.Add(gp_Pnt(float(x), float(y), 0.0))
    mp.Close()
    return mp.Wire()


def _volume_mm3(solid) -> float:
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(solid, props)
    return float(props.Mass())


def _write(solid) -> bytes:
    cq = _cadquery()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "part.step"
        cq.exporters.export(cq.Shape.cast(solid), str(path), "STEP")
        return path.read_bytes()


def write_step(path: str | Path, outline, thickness_mm: float) -> Path:
    """Write `step_bytes` atomically (nothing is written when CadQuery or the input fails)."""
    return write_bytes(path, step_bytes(outline, thickness_mm))
