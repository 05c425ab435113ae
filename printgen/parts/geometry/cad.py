"""STEP export through CadQuery (the optional `cad` extra, imported only when asked for):
the part's plan-view outline (`solid.net_outline` / `cable.cable_outline`) extruded as a
B-rep, in mm. The input is checked before CadQuery is imported or anything is written."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from printgen.errors import GeometryError
from printgen.outputs import write_bytes
from printgen.parts.geometry.cable import check_positive_mm

INSTALL_HINT = "pip install 'printgen[cad]'"  # quoted: zsh globs brackets


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
    """STEP text of a shapely polygon (with holes) extruded by `thickness_mm` (mm)."""
    check_positive_mm(thickness_mm, "STEP part thickness")
    poly = _single_polygon(outline)
    cq = _cadquery()

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


def write_step(path: str | Path, outline, thickness_mm: float) -> Path:
    """Write `step_bytes` atomically (nothing is written when CadQuery or the input fails)."""
    return write_bytes(path, step_bytes(outline, thickness_mm))
