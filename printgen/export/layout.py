"""Place a part on the printer bed: turned (about z) if it only fits that way, centred, on z=0.
The same placement as the direct G-code (`gcode.toolpath.place_on_bed`)."""

from __future__ import annotations

import numpy as np

from printgen.gcode.toolpath import place_on_bed
from printgen.printers import Printer


def place_mesh(mesh, printer: Printer, name: str):
    """A copy of `mesh` turned and moved to the bed centre; PrintabilityError if it cannot fit.

    Returns (placed mesh, angle in degrees).
    """
    lo, hi = mesh.bounds
    size = (hi - lo)[:2]
    angle, centre = place_on_bed(size, printer, where=name)
    placed = mesh.copy()
    placed.apply_translation(-(lo + hi) / 2 * np.array([1, 1, 0]) - np.array([0, 0, lo[2]]))
    c, s = np.cos(angle), np.sin(angle)
    rot = np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])
    placed.apply_transform(rot)
    placed.apply_translation([centre[0], centre[1], 0.0])
    return placed, float(np.degrees(angle))
