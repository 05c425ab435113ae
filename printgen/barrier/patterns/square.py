"""The square net: strands across and up the barrier (the simple barrier of the scale series,
Lambert et al. 2023, doi:10.1061/JHEND8.HYENG-13070). Its mesh is the square's side
`mesh_x` (both ways; a printed square net must have mesh_y = mesh_x, `check_square`). Under a
stretch eps along the load the strands up the barrier strain eps and carry it, one per mesh
across: N = E A / a_across * eps; the strands across carry nothing (transverse strain blocked).

Graph: nodes at (i a, j a); strands up (family +1, the columns i = 1 .. nx-1) and across
(family -1, the rows j = 1 .. ny-1) from border to border; the perimeter rows and columns are
the border loop (family 0). On the prototype they are strands of the net like the others
(`edge_strands`); on the printed net they are the border frame, laid along the same lines.
"""

from __future__ import annotations

import math

import numpy as np

from printgen.barrier.graph import NetGraph, check_lengths
from printgen.barrier.patterns import Law, NetPattern
from printgen.errors import GeometryError

MIN_MESHES = 1  # at least one mesh each way
SQUARE_REL = 1e-6  # mesh_x and mesh_y of a square mesh agree to this (rounded mm values)


def square_factor(mesh_across: float) -> float:
    """1 / a_across (1/m): a square net's strands along the load, one per mesh."""
    return 1.0 / mesh_across


def membrane_factor(mesh_along: float, mesh_across: float) -> float:
    return square_factor(mesh_across)


def strand_force(n: float, mesh_along: float, mesh_across: float) -> float:
    """Strand tension (N) under a membrane force `n` N/m: one strand per a_across carries it."""
    return n * mesh_across


def strand_law(knees: tuple[float, ...], slopes: tuple[float, ...], mesh_along: float,
               mesh_across: float) -> Law:
    """Strand law of a square net with membrane law (knees, slopes N/m): the strands along
    the load strain as the net (same knees) and each carries a_across of its width."""
    return Law(tuple(knees), tuple(s * mesh_across for s in slopes))


def span(length: float, mesh: float) -> float:
    """`length` rounded to whole meshes (the rule of `square_graph`)."""
    return round(length / mesh) * mesh


def square_nodes(width: float, height: float, mesh_x: float, mesh_y: float) -> int:
    """Nodes of `square_graph` (any length unit; the mesh is `mesh_x` both ways)."""
    return (round(width / mesh_x) + 1) * (round(height / mesh_x) + 1)


def check_square(mesh_x: float, mesh_y: float | None, where: str = "net") -> None:
    """GeometryError unless the mesh is square (mesh_y None: taken as mesh_x)."""
    if mesh_y is not None and not math.isclose(mesh_x, mesh_y, rel_tol=SQUARE_REL):
        raise GeometryError(f"{where}: a square mesh needs mesh_x = mesh_y, got {mesh_x:g} x "
                            f"{mesh_y:g}; give equal sides or use pattern \"diamond\"")


def square_graph(width_mm: float, height_mm: float, mesh_x_mm: float,
                 mesh_y_mm: float | None = None) -> NetGraph:
    """A square-mesh net (strands across and up) of side `mesh_x_mm` as a NetGraph."""
    mesh_mm = mesh_x_mm
    check_lengths(width=width_mm, height=height_mm, mesh_x=mesh_mm)
    nx, ny = round(width_mm / mesh_mm), round(height_mm / mesh_mm)
    if min(nx, ny) < MIN_MESHES:
        raise GeometryError(f"net {width_mm:g} x {height_mm:g} mm holds {nx} x {ny} square "
                            f"meshes of {mesh_mm:g} mm; need at least {MIN_MESHES} each way: "
                            "use a smaller mesh or a larger panel")
    ii, jj = np.meshgrid(np.arange(nx + 1), np.arange(ny + 1), indexing="ij")
    nodes = np.column_stack([ii.ravel() * mesh_mm, jj.ravel() * mesh_mm]).astype(float)
    idx = np.arange((nx + 1) * (ny + 1)).reshape(nx + 1, ny + 1)
    across = np.column_stack([idx[:-1].ravel(), idx[1:].ravel()])  # row j of each piece: jj
    up = np.column_stack([idx[:, :-1].ravel(), idx[:, 1:].ravel()])
    on_edge_row = np.isin(jj[:-1].ravel(), (0, ny))
    on_edge_col = np.isin(ii[:, :-1].ravel(), (0, nx))
    family = np.concatenate([np.where(on_edge_row, 0, -1), np.where(on_edge_col, 0, 1)])
    strands = [idx[i, :] for i in range(1, nx)] + [idx[:, j] for j in range(1, ny)]
    ring = np.concatenate([idx[:, 0], idx[-1, 1:], idx[-2::-1, -1], idx[0, -2:0:-1]])
    return NetGraph(nodes, np.vstack([across, up]), family, strands, ring,
                    (float(mesh_mm), float(mesh_mm)), (nx, ny))


PATTERN = NetPattern("square", square_graph, membrane_factor, strand_law, strand_force,
                     span, square_nodes, edge_strands=True, mesh_name="mesh side",
                     check_mesh=check_square, panel_test=True)
