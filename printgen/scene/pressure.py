"""Water pressure normal to the deformed net: the loading test's folded film lies on
the net and the water presses it normal to its surface, so each node's load is the pressure
at its height times its share of the net's current area vector, instead of a force along the
flow (`solver.Hydrostatic`, the reference's section 3).

Faces: the meshes of the net's lattice (the diamond's or the square's: four strand corners; three at
the edges, where the lattice cuts a mesh), found from the nodes' lattice positions. A node's area
vector is a quarter (a third for an edge triangle) of each face it is a corner of, oriented
downstream at rest and scaled so that at rest its magnitude is the scene's A* (the same tributary
area as the load along the flow): the two variants then differ only by the direction of the force
and by the growth of the net's area as it stretches.

`loads_function` gives a scene's loads at each relative loading: its load case's, with the
hydrostatic part normal to the net when the scene's pressure option says so.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from printgen import solver
from printgen.barrier.loads import FLOW, LoadCase, LoadsAt, Site, get_load
from printgen.scene.scenes import BarrierScene
from printgen.units import RHO_WATER, G


def lattice_faces(nodes: np.ndarray, elements: np.ndarray) -> list[np.ndarray]:
    """The net's meshes as node cycles (k,) of 3 or 4 nodes, from the lattice of the strands
    `elements` (their non-zero x and z steps: the diamond's half-diagonals, the square's
    side). A candidate is a diamond ring around a lattice point or a square cell from one;
    it is a mesh when it has 3 or 4 nodes and at least two of its sides are strands."""
    d = np.abs(nodes[elements[:, 1]] - nodes[elements[:, 0]])
    hx, hz = (float(np.median(c[c > 0])) for c in (d[:, 0], d[:, 2]))
    ij = np.column_stack([np.round(nodes[:, 0] / hx), np.round(nodes[:, 2] / hz)]).astype(int)
    where = {(int(i), int(j)): k for k, (i, j) in enumerate(ij)}
    linked = {(min(a, b), max(a, b)) for a, b in elements}
    faces = []
    for ci, cj in {(i + di, j + dj) for i, j in where for di, dj in ((1, 0), (-1, 0))}:
        for corners in (((ci - 1, cj), (ci, cj - 1), (ci + 1, cj), (ci, cj + 1)),
                        ((ci, cj), (ci + 1, cj), (ci + 1, cj + 1), (ci, cj + 1))):
            ring = [r for r in (where.get(c) for c in corners) if r is not None]
            pairs = zip(ring, ring[1:] + ring[:1], strict=True)
            if len(ring) >= 3 and sum((min(a, b), max(a, b)) in linked for a, b in pairs) >= 2:
                faces.append(np.array(ring))
    return faces


def area_vectors(x: np.ndarray, faces: list[np.ndarray], n: int) -> np.ndarray:
    """(n, 3) each node's share of its faces' area vectors (m^2) at positions x."""
    out = np.zeros((n, 3))
    for size in (3, 4):
        f = np.array([r for r in faces if len(r) == size], dtype=int).reshape(-1, size)
        if not len(f):
            continue
        p = x[f]
        if size == 4:
            a = 0.5 * np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1])
        else:
            a = 0.5 * np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
        np.add.at(out, f, np.repeat(a[:, None, :] / size, size, axis=1))
    return out


@dataclass(frozen=True)
class NormalPressure:
    """rho g (level - z) on `nodes` (below the water level) along their current area vector,
    scaled to A* at rest (see the module). A solver load: evaluate(x) -> (nodes, forces (k, 3)
    N, d(forces)/dz (k, 3) N/m, the node's own-height term only)."""

    nodes: np.ndarray
    faces: tuple[np.ndarray, ...]
    rest_scale: np.ndarray  # (n,) A* / |area vector at rest| per node (0: no face)
    sign: float  # +1 when the rest area vectors point downstream (+y)
    level: float
    n: int
    rho: float = RHO_WATER
    g: float = G

    def evaluate(self, x: np.ndarray):
        idx = np.asarray(self.nodes, dtype=int)
        a = self.sign * area_vectors(x, list(self.faces), self.n)[idx]
        a *= self.rest_scale[idx, None]
        head = np.maximum(self.level - x[idx, 2], 0.0)
        f = (self.rho * self.g * head)[:, None] * a
        wet = (self.level - x[idx, 2]) > 0
        return idx, f, (-self.rho * self.g * wet)[:, None] * a


def normal_pressure(nodes: np.ndarray, elements: np.ndarray, free: np.ndarray,
                    area_per_node: float, level: float) -> NormalPressure:
    """The NormalPressure of a net at rest positions `nodes` with strands `elements`."""
    faces = lattice_faces(nodes, elements)
    rest = area_vectors(nodes, faces, len(nodes))
    sign = 1.0 if rest[:, 1].sum() >= 0 else -1.0
    mag = np.linalg.norm(rest, axis=1)
    scale = np.divide(area_per_node, mag, out=np.zeros_like(mag), where=mag > 0)
    return NormalPressure(free, tuple(faces), scale, sign, level, len(nodes))


def loads_function(s: BarrierScene, *, load: str | LoadCase | None = None,
                   site: Site | None = None) -> LoadsAt:
    """Loads at relative loading r of load case `load` (default hydrostatic) on the scene's
    free nodes, at `site` (the sensor wires are part of the solver net,
    `printgen.scene.solvernet.build`). With the scene's pressure option "normal" the
    hydrostatic part presses normal to the deformed net (the folded film presses normal to
    the surface) instead of along the flow."""
    loads_at = get_load(load).loads_for(s, site)
    if s.pressure != "normal":
        return loads_at
    free = np.flatnonzero(~s.fixed)
    normal = normal_pressure(s.nodes, s.elements[s.element_law == 0], free, s.area_per_node,
                             0.0)

    def normal_at(r: float) -> list:
        return [dataclasses.replace(normal, level=f.level)  # the water behind a jam stays along
                if isinstance(f, solver.Hydrostatic) and f.direction == tuple(FLOW) else f
                for f in loads_at(r)]

    return normal_at
