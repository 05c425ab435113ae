"""Plan-view measures of a net's straight strands (mm), read from its `NetGraph` whatever the
pattern (`printgen.barrier.patterns`: the diamond's diagonals, the square's strands up and
across): the angle at the crossings, the spacing of parallel strands, how the strands meet
the panel's edge. The meshes (`solid`) and the toolpath volumes (`printgen.parts.gcode`) use
them for their checks and analytic areas.
"""

from __future__ import annotations

import numpy as np

from printgen.barrier.graph import NetGraph

EDGE_TOL_MM = 1e-9  # a strand end lies on an edge within this (coordinates built from the mesh)


def strand_ends(g: NetGraph) -> np.ndarray:
    """(k, 2, 2) start and end point of each strand (mm)."""
    return np.array([[g.nodes_mm[s[0]], g.nodes_mm[s[-1]]] for s in g.strands]).reshape(-1, 2, 2)


def strand_units(g: NetGraph) -> np.ndarray:
    """(k, 2) unit direction of each strand, start to end."""
    d = np.diff(strand_ends(g), axis=1)[:, 0]
    return d / np.hypot(d[:, 0], d[:, 1])[:, None]


def crossing_sin(g: NetGraph) -> float:
    """sin of the angle between the strands that cross (1 when no two strands cross)."""
    u = strand_units(g)
    if not len(u):
        return 1.0
    return float(np.abs(u[:, 0] * u[0, 1] - u[:, 1] * u[0, 0]).max())


def crossing_direction(g: NetGraph, u: np.ndarray) -> np.ndarray:
    """Unit direction of the strands that cross a strand of direction `u` (the diamond's other
    diagonal, the square's strands across the ones up); `u` itself when none cross it. The
    patterns list one family's strands, then the other's: the first and last strands stand
    for the two (constant time: the toolpath asks once per bead)."""
    if not g.strands:
        return np.asarray(u)
    d = np.array([g.nodes_mm[s[-1]] - g.nodes_mm[s[0]] for s in (g.strands[0], g.strands[-1])])
    d /= np.hypot(d[:, 0], d[:, 1])[:, None]
    cross = np.abs(d[:, 0] * u[1] - d[:, 1] * u[0])
    return d[int(np.argmax(cross))] if cross.max() > 0 else np.asarray(u)


def parallel_spacing(g: NetGraph) -> float:
    """Smallest distance between the centre lines of two neighbouring parallel strands (mm;
    inf for a net without two parallel strands)."""
    ends, u = strand_ends(g), strand_units(g)
    out = np.inf
    for fam in np.unique(np.round(np.abs(u @ u[0]), 9)):
        same = np.isclose(np.abs(u @ u[0]), fam)
        normal = np.array([-u[same][0, 1], u[same][0, 0]])
        offsets = np.unique(np.round(ends[same, 0] @ normal, 9))
        if len(offsets) > 1:
            out = min(out, float(np.diff(offsets).min()))
    return out


def _end_shares(g: NetGraph) -> tuple[np.ndarray, np.ndarray]:
    """(2k,) |u . n| and |u . t| at each strand end: n the normal, t the tangent of the panel
    edge the end lies on (a strand end on the bottom or top edge meets it along y)."""
    ends = strand_ends(g).reshape(-1, 2)
    u = np.repeat(strand_units(g), 2, axis=0)
    sy = g.size_mm[1]
    on_top_bottom = (np.abs(ends[:, 1]) < EDGE_TOL_MM) | (np.abs(ends[:, 1] - sy) < EDGE_TOL_MM)
    normal = np.where(on_top_bottom, np.abs(u[:, 1]), np.abs(u[:, 0]))
    tangent = np.where(on_top_bottom, np.abs(u[:, 0]), np.abs(u[:, 1]))
    return normal, tangent


def end_sin(g: NetGraph) -> np.ndarray:
    """(2k,) sin of the angle between each strand end and the edge it meets, strand by
    strand (start, end)."""
    return _end_shares(g)[0]


def end_poke(g: NetGraph, width_mm: float) -> float:
    """How far across the edge (both sides together, mm) the flat end of a band of
    `width_mm` reaches where its strand meets the edge at a slant (0 when square to it)."""
    tangent = _end_shares(g)[1]
    return float(width_mm * tangent.max()) if len(tangent) else 0.0


def first_inner_node_mm(g: NetGraph) -> float:
    """Distance from the panel edge to the nearest node inside it (the first crossing, mm)."""
    inner = np.setdiff1d(np.arange(len(g.nodes_mm)), g.border)
    if not len(inner):
        return np.inf
    (x, y), (sx, sy) = g.nodes_mm[inner].T, g.size_mm
    return float(np.min(np.minimum(np.minimum(x, sx - x), np.minimum(y, sy - y))))
