"""STEP export through CadQuery (the optional `cad` extra, imported only when asked for):
the part's plan-view outline (`solid.net_outline` / `cable_outline`) extruded as a B-rep."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from printgen.errors import GeometryError


def _cadquery():
    try:
        import cadquery
    except ImportError as exc:
        raise GeometryError("STEP output needs CadQuery: pip install 'printgen[cad]' "
                            "(or leave out --step)") from exc
    return cadquery


def step_bytes(outline, thickness_mm: float) -> bytes:
    """STEP text of a shapely polygon (with holes) extruded by `thickness_mm` (mm)."""
    cq = _cadquery()
    polys = list(getattr(outline, "geoms", [outline]))
    if len(polys) != 1:
        raise GeometryError(f"outline has {len(polys)} pieces; a STEP part must be one body")
    poly = polys[0]

    def prism(ring) -> object:
        pts = [tuple(map(float, p)) for p in np.asarray(ring.coords)[:-1]]
        return cq.Workplane("XY").polyline(pts).close().extrude(thickness_mm)

    body = prism(poly.exterior)
    for hole in poly.interiors:
        body = body.cut(prism(hole))
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "part.step"
        cq.exporters.export(body, str(path), "STEP")
        return path.read_bytes()
