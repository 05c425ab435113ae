"""Place parts on the printer bed (mm): inside the bed less its margins, on z = 0.

A part that does not fit as modelled is turned about z by the smallest angle (0.5 deg steps,
up to 90 deg, so the diagonal is tried) at which its real footprint - the convex hull of its
vertices, not its bounding box - fits; the angle is returned, so callers can report it. The
direct G-code turns parts by the same rule applied to their bounding box, so its angle can be
a fraction of a degree larger for round eyelets. Several parts share one plate in shelves
(rows), `PART_GAP_MM` apart, the whole arrangement centred on the bed.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from printgen.errors import GeometryError, PrintabilityError
from printgen.inputs.printers import Printer

if TYPE_CHECKING:  # pragma: no cover
    import trimesh

ANGLE_STEP_DEG = 0.5  # the sweep of the direct G-code placement (181 angles over 90 deg)
PART_GAP_MM = 5.0  # between parts on one plate: room for a skirt, and no fused brims
FIT_TOL_MM = 1e-9  # round-off allowance when comparing a footprint with the usable bed


@dataclass(frozen=True)
class Placement:
    """A part moved onto the bed: `mesh` in bed coordinates (mm), turned by `angle_deg`."""

    name: str
    mesh: trimesh.Trimesh
    angle_deg: float

def usable_bed_mm(printer: Printer) -> np.ndarray:
    """(2,) float, mm: the bed less its margin on every side."""
    return np.array([printer.bed_x_mm, printer.bed_y_mm]) - 2 * printer.bed_margin_mm


def _hull_xy(mesh) -> np.ndarray:
    from scipy.spatial import ConvexHull

    xy = np.asarray(mesh.vertices)[:, :2]
    return xy[ConvexHull(xy).vertices]


def _extents(hull: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """(m, 2) float, mm: x and y extent of the hull turned by each angle (rad)."""
    c, s = np.cos(angles)[:, None], np.sin(angles)[:, None]
    x = hull[:, 0] * c - hull[:, 1] * s
    y = hull[:, 0] * s + hull[:, 1] * c
    return np.column_stack([np.ptp(x, axis=1), np.ptp(y, axis=1)])


def fit_angle(mesh, printer: Printer, name: str) -> float:
    """Smallest turn (deg, 0 to 90) at which `mesh` fits the usable bed; PrintabilityError
    naming the part size, the bed and the fixes when no angle does."""
    if len(mesh.vertices) == 0:
        raise GeometryError(f"{name}: the mesh is empty")
    lo, hi = mesh.bounds
    size = hi - lo
    usable = usable_bed_mm(printer)
    where = (f"the usable {usable[0]:g} x {usable[1]:g} mm of printer {printer.key} (bed "
             f"{printer.bed_x_mm:g} x {printer.bed_y_mm:g} mm less {printer.bed_margin_mm:g} mm "
             "margins)")
    if size[2] > printer.max_height_mm + FIT_TOL_MM:
        raise PrintabilityError(f"{name}: part {size[2]:.3g} mm high exceeds the "
                                f"{printer.max_height_mm:g} mm build height of {printer.key}; "
                                "choose a taller printer or split the part")
    degrees = np.arange(0.0, 90.0 + ANGLE_STEP_DEG / 2, ANGLE_STEP_DEG)
    angles = np.radians(degrees)
    ext = _extents(_hull_xy(mesh), angles)
    fits = np.all(ext <= usable + FIT_TOL_MM, axis=1)
    if not fits.any():
        best = int(np.argmin(np.max(ext / usable, axis=1)))
        raise PrintabilityError(
            f"{name}: part {size[0]:.1f} x {size[1]:.1f} mm does not fit {where}, not even "
            f"turned diagonally (best: {degrees[best]:g} deg, "
            f"{ext[best, 0]:.1f} x {ext[best, 1]:.1f} mm); choose a printer with a larger bed "
            "(--printer) or a larger lambda (a smaller model): printgen select says which "
            "printers and which lambda fit")
    return float(degrees[int(np.argmax(fits))])


def _turned(mesh, angle_deg: float):
    """A copy of `mesh` turned about z by `angle_deg`, its footprint's lower-left at (0, 0)
    and its bottom on z = 0."""
    out = mesh.copy()
    a = np.radians(angle_deg)
    c, s = np.cos(a), np.sin(a)
    out.apply_transform(np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]]))
    out.apply_translation(-out.bounds[0])
    return out


def place_mesh(mesh, printer: Printer, name: str) -> tuple[trimesh.Trimesh, float]:
    """A copy of `mesh` turned if it must be and centred on the bed, on z = 0.

    Returns (placed mesh, angle in degrees); PrintabilityError if it cannot fit.
    """
    p = layout_parts([(name, mesh)], printer)[0]
    return p.mesh, p.angle_deg


def layout_parts(parts: list[tuple[str, trimesh.Trimesh]], printer: Printer) -> list[Placement]:
    """Lay named meshes out together on one bed (shelves, tallest first; input order kept in
    the result). PrintabilityError if one part or all of them together do not fit."""
    if not parts:
        raise GeometryError("no parts to lay out")
    angles = [fit_angle(m, printer, n) for n, m in parts]
    turned = [_turned(m, a) for (_, m), a in zip(parts, angles, strict=True)]
    sizes = np.array([t.bounds[1, :2] for t in turned])
    usable = usable_bed_mm(printer)
    origin = np.zeros((len(parts), 2))
    x = y = row_h = 0.0
    for k in sorted(range(len(parts)), key=lambda k: (-sizes[k, 1], k)):
        if x > 0 and x + sizes[k, 0] > usable[0] + FIT_TOL_MM:
            x, y, row_h = 0.0, y + row_h + PART_GAP_MM, 0.0
        origin[k] = (x, y)
        x += sizes[k, 0] + PART_GAP_MM
        row_h = max(row_h, sizes[k, 1])
    extent = (origin + sizes).max(axis=0)
    if np.any(extent > usable + FIT_TOL_MM):
        names = ", ".join(n for n, _ in parts)
        raise PrintabilityError(
            f"parts {names} need {extent[0]:.1f} x {extent[1]:.1f} mm together ({PART_GAP_MM:g} "
            f"mm apart) but printer {printer.key} offers {usable[0]:g} x {usable[1]:g} mm "
            "inside its margins; put them on separate plates (one file per part)")
    shift = np.array([printer.bed_x_mm, printer.bed_y_mm]) / 2 - extent / 2
    out = []
    for (name, _), t, a, o in zip(parts, turned, angles, origin, strict=True):
        t.apply_translation([*(o + shift), 0.0])
        out.append(Placement(name, t, a))
    return out
