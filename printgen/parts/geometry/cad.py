"""STEP export through CadQuery's OCP kernel (the optional `cad` extra, imported only when
asked for): the part's plan-view outline (`solid.net_outline` / `cable.cable_outline`) as
one face swept once into a prism, in mm. The input is checked before OCP is imported or
anything is written."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from printgen.errors import GeometryError
from printgen.outputs import write_bytes
from printgen.parts.geometry.cable import check_positive_mm

INSTALL_HINT = "pip install 'printgen[cad]'"  # quoted: zsh globs brackets
STEP_SIMPLIFY_MM = 0.005  # outline vertices dropped within 5 um (circles: 128 -> ~20 sides)
STEP_VOLUME_TOL = 1e-3  # the prism's volume vs the mesh outline's area x thickness


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

    One planar face (outer wire plus one wire per hole) swept once into a prism: no boolean
    per hole. Circles are thinned to STEP_SIMPLIFY_MM (fewer faces to write); the solid's
    volume is checked against the mesh outline's area x thickness.
    """
    check_positive_mm(thickness_mm, "STEP part thickness")
    full = _single_polygon(outline)
    from shapely.geometry.polygon import orient

    # exterior counter-clockwise, holes clockwise; circles thinned to STEP_SIMPLIFY_MM
    poly = orient(full.simplify(STEP_SIMPLIFY_MM, preserve_topology=True), sign=1.0)
    _cadquery()  # the install hint when CadQuery (and its OCP kernel) is missing
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism
    from OCP.gp import gp_Vec

    maker = BRepBuilderAPI_MakeFace(_wire(poly.exterior), True)
    for hole in poly.interiors:
        maker.Add(_wire(hole))
    if not maker.IsDone():
        raise GeometryError("STEP: the outline does not make a planar face")
    solid = BRepPrimAPI_MakePrism(maker.Face(), gp_Vec(0.0, 0.0, thickness_mm)).Shape()
    volume = _volume_mm3(solid)
    expected = full.area * thickness_mm
    if not poly.is_valid or abs(volume / expected - 1) > STEP_VOLUME_TOL:
        raise GeometryError(f"STEP: solid volume {volume:.6g} mm^3 differs from the outline's "
                            f"{expected:.6g} mm^3")
    return _write(solid)


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
