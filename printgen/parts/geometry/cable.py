"""Border cables as plan-view outlines (shapely, mm) and their analytic volume.

A cable is a straight strip of the section width between two eyelet rings (inner and outer
diameter), eyelet centres `length_mm` apart along x, centred on the origin, extruded later to
the section thickness by `printgen.parts.geometry.solid`. Circles are polygons of
`CIRCLE_SEGMENTS` sides with the circle's area (radius scaled up by ~2e-4), so the mesh
volume matches the analytic one; the extent grows by the same factor (< 1 um at 3 mm).
Needs shapely (the `geometry` extra) for the outline; the analytic volume is numpy only.
"""

from __future__ import annotations

import numpy as np

from printgen.errors import GeometryError
from printgen.scaling.record import CableDesign

CIRCLE_SEGMENTS = 128  # eyelet polygon sides: chord sag 3e-4 x radius; area kept exact


def require_shapely():
    """The shapely module, or GeometryError with the install hint."""
    try:
        import shapely
    except ImportError as exc:  # pragma: no cover - depends on the install
        raise GeometryError("outlines need the geometry extra (shapely missing): "
                            "pip install 'printgen[geometry]'") from exc
    return shapely


def check_positive_mm(value: float, what: str) -> None:
    """GeometryError unless `value` is a positive finite length in mm."""
    if not np.isfinite(value) or value <= 0:
        raise GeometryError(f"{what} = {value!r} mm must be a positive finite length")


def circle_scale(n: int = CIRCLE_SEGMENTS) -> float:
    """Radius factor giving a regular n-gon the area of its circle."""
    return float(np.sqrt(2 * np.pi / (n * np.sin(2 * np.pi / n))))


def circle_points(cx: float, cy: float, r: float, n: int = CIRCLE_SEGMENTS) -> np.ndarray:
    """(n, 2) float, mm: counter-clockwise regular n-gon of the circle's area, vertex at 0 deg."""
    t = np.arange(n) * (2 * np.pi / n)
    rr = r * circle_scale(n)
    return np.column_stack([cx + rr * np.cos(t), cy + rr * np.sin(t)])


def check_cable(cable: CableDesign, hole_compensation_mm: float = 0.0) -> None:
    """Raise GeometryError when the cable cannot be built (with the value, limit and fix)."""
    name = f"cable {cable.name}"
    if not (np.isfinite(hole_compensation_mm) and 0 <= hole_compensation_mm < 1.0):
        raise GeometryError(f"hole compensation {hole_compensation_mm!r} mm must lie in 0..1 mm;"
                            " fix hole_compensation_mm in the printer profile")
    check_positive_mm(cable.length_mm, f"{name} length")
    check_positive_mm(cable.section.width_mm, f"{name} strip width")
    check_positive_mm(cable.section.thickness_mm, f"{name} thickness")
    if not (np.isfinite(cable.eyelet_outer_mm)
            and cable.eyelet_outer_mm > cable.eyelet_inner_mm + hole_compensation_mm > 0):
        raise GeometryError(f"{name}: eyelet diameters inner {cable.eyelet_inner_mm:g} mm, "
                            f"outer {cable.eyelet_outer_mm:g} mm; need 0 < inner < outer "
                            "(fix eyelet_inner_mm / eyelet_outer_mm of the design)")
    if cable.section.width_mm >= cable.eyelet_outer_mm:
        raise GeometryError(f"{name}: strip {cable.section.width_mm:g} mm is not narrower than "
                            f"the eyelet ({cable.eyelet_outer_mm:g} mm outer diameter); widen "
                            "the eyelet")
    if cable.length_mm <= cable.eyelet_outer_mm:
        raise GeometryError(f"{name}: length {cable.length_mm:g} mm leaves no strip between "
                            f"eyelets of {cable.eyelet_outer_mm:g} mm outer diameter; the "
                            "eyelet centres must be more than one outer diameter apart")


def cable_outline(cable: CableDesign, hole_compensation_mm: float = 0.0):
    """Plan view of a cable: shapely Polygon with two holes (mm, centred, along x); the holes
    are `hole_compensation_mm` larger than the design's (FDM holes print small)."""
    check_cable(cable, hole_compensation_mm)
    shapely = require_shapely()
    from shapely.geometry import Polygon, box

    half, w = cable.length_mm / 2, cable.section.width_mm
    ro, ri = cable.eyelet_outer_mm / 2, (cable.eyelet_inner_mm + hole_compensation_mm) / 2
    ends = (-half, half)
    outline = shapely.unary_union([box(-half, -w / 2, half, w / 2)]
                                  + [Polygon(circle_points(x, 0.0, ro)) for x in ends])
    holes = shapely.unary_union([Polygon(circle_points(x, 0.0, ri)) for x in ends])
    return outline.difference(holes)


def analytic_cable_area(cable: CableDesign, hole_compensation_mm: float = 0.0) -> float:
    """Plan area of a cable (mm^2): two annuli plus the strip outside the two outer discs."""
    check_cable(cable, hole_compensation_mm)
    ro, ri = cable.eyelet_outer_mm / 2, (cable.eyelet_inner_mm + hole_compensation_mm) / 2
    w = cable.section.width_mm
    # strip |y| <= w/2 inside one disc, on the strip's side of its centre
    in_disc = (w / 2) * np.sqrt(ro * ro - w * w / 4) + ro * ro * np.arcsin(w / (2 * ro))
    return float(2 * np.pi * (ro * ro - ri * ri) + cable.length_mm * w - 2 * in_disc)


def analytic_cable_volume(cable: CableDesign, hole_compensation_mm: float = 0.0) -> float:
    """Volume of a cable (mm^3): plan area x section thickness."""
    return analytic_cable_area(cable, hole_compensation_mm) * cable.section.thickness_mm
