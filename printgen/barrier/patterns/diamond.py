"""The diamond net: strands on both diagonals of each mesh, the printed model's pattern.

Lattice: strand crossings at (i * a/2, j * b/2) with i + j even, where a is the mesh diagonal
along x (across the barrier) and b the diagonal along y (up the barrier). Strands are straight
lines of slope +b/a (family +1) and -b/a (family -1) from border to border; a border strand
(family 0) runs around the perimeter through every boundary node and the four corners. The
mesh diagonals are kept exact: the panel size is rounded to whole half-diagonals (`span`).

Membrane law: under a stretch eps along the load (transverse strain blocked, as in the panel
test) a strand at angle theta to the cross direction strains eps sin^2(theta); with
2 / a_across strands per unit width, the force per unit width is
N = 2 E A sin^3(theta) / a_across * eps.
"""

from __future__ import annotations

import math

import numpy as np

from printgen.barrier.graph import NetGraph, check_lengths
from printgen.barrier.patterns import Law, NetPattern, any_mesh
from printgen.errors import GeometryError

MIN_HALF_CELLS = 2  # fewer half-meshes across than this is not a net


def diamond_sin(mesh_along: float, mesh_across: float) -> float:
    """sin(theta) of a diamond strand, theta its angle to the cross direction."""
    return (mesh_along / 2) / math.hypot(mesh_along / 2, mesh_across / 2)


def diamond_factor(mesh_along: float, mesh_across: float) -> float:
    """2 sin^3(theta) / a_across (1/m) of a diamond net loaded along `mesh_along`."""
    sin = diamond_sin(mesh_along, mesh_across)
    return 2 * sin**3 / mesh_across


def strand_law(knees: tuple[float, ...], slopes: tuple[float, ...], mesh_along: float,
               mesh_across: float) -> Law:
    """Strand force law whose diamond net has the membrane law (knees, slopes N/m).

    Stretching the net by eps along the load strains a strand by eps sin^2(theta), and the
    strands carry N = (2 / a_across) F sin(theta) per unit width; so the strand law has knees
    eps_k sin^2(theta) and slopes N' a_across / (2 sin^3(theta)).
    """
    sin = diamond_sin(mesh_along, mesh_across)
    f = 1.0 / (diamond_factor(mesh_along, mesh_across))
    return Law(tuple(k * sin * sin for k in knees), tuple(s * f for s in slopes))


def strand_force(n: float, mesh_along: float, mesh_across: float) -> float:
    """Strand tension (N) under a membrane force `n` N/m along the load: 2 / a_across
    strands per unit width carry it, each at sin(theta) to the cross direction."""
    return n * mesh_across / (2 * diamond_sin(mesh_along, mesh_across))


def lockup_strain(mesh_along: float, mesh_across: float) -> float:
    """Panel strain at which the diamonds' strands lie along the load (their meshes closed
    across it): strand length over its along-load half-diagonal, minus 1."""
    return math.hypot(mesh_along, mesh_across) / mesh_along - 1.0


def span(length: float, diagonal: float) -> float:
    """`length` rounded to whole half-diagonals (the rule of `diamond_net`)."""
    return round(2 * length / diagonal) * diagonal / 2


def diamond_nodes(width: float, height: float, mesh_x: float, mesh_y: float) -> int:
    """Nodes of `diamond_net` (any length unit)."""
    nx, ny = max(round(2 * width / mesh_x), 1), max(round(2 * height / mesh_y), 1)
    odd_corners = sum((i + j) % 2 for i in (0, nx) for j in (0, ny))  # kept as nodes too
    return ((nx + 1) * (ny + 1) + 1) // 2 + odd_corners


def diamond_net(width_mm: float, height_mm: float, mesh_x_mm: float, mesh_y_mm: float) -> NetGraph:
    """Build the diamond-net graph of a panel about `width_mm` x `height_mm`.

    The panel is nx = round(2 W / a) half-diagonals wide and ny = round(2 H / b) high.
    """
    check_lengths(width=width_mm, height=height_mm, mesh_x=mesh_x_mm, mesh_y=mesh_y_mm)
    nx, ny = round(2 * width_mm / mesh_x_mm), round(2 * height_mm / mesh_y_mm)
    if min(nx, ny) < MIN_HALF_CELLS:
        raise GeometryError(
            f"net {width_mm:g} x {height_mm:g} mm holds only {nx} x {ny} half-meshes of "
            f"{mesh_x_mm:g} x {mesh_y_mm:g} mm; need at least {MIN_HALF_CELLS} each way: "
            "use a smaller mesh or a larger panel")
    hx, hy = mesh_x_mm / 2, mesh_y_mm / 2
    ii, jj = np.meshgrid(np.arange(nx + 1), np.arange(ny + 1), indexing="ij")
    keep = ((ii + jj) % 2 == 0) | _is_corner(ii, jj, nx, ny)
    index = -np.ones((nx + 1, ny + 1), dtype=int)
    index[keep] = np.arange(int(keep.sum()))
    nodes = np.column_stack([ii[keep] * hx, jj[keep] * hy]).astype(float)

    strands = _strands(index, nx, ny)
    border = _border_loop(index, nx, ny)
    segs, fam = [], []
    for s in strands:
        sign = 1 if (nodes[s[-1], 1] - nodes[s[0], 1]) > 0 else -1
        segs.append(np.column_stack([s[:-1], s[1:]]))
        fam.append(np.full(len(s) - 1, sign))
    segs.append(np.column_stack([border, np.roll(border, -1)]))
    fam.append(np.zeros(len(border), dtype=int))
    return NetGraph(nodes, np.vstack(segs), np.concatenate(fam), strands, border,
                    (float(mesh_x_mm), float(mesh_y_mm)), (nx, ny))


def _is_corner(ii: np.ndarray, jj: np.ndarray, nx: int, ny: int) -> np.ndarray:
    return np.isin(ii, (0, nx)) & np.isin(jj, (0, ny))


def _strands(index: np.ndarray, nx: int, ny: int) -> list[np.ndarray]:
    """Diagonal strands with at least one segment: walk (+1, +1) and (+1, -1) from each start."""
    out = []
    for di, dj in ((1, 1), (1, -1)):
        for i0 in range(nx + 1):
            for j0 in range(ny + 1):
                prev_i, prev_j = i0 - di, j0 - dj
                if index[i0, j0] < 0 or (i0 + j0) % 2:
                    continue
                if 0 <= prev_i <= nx and 0 <= prev_j <= ny:
                    continue  # not the start of a strand
                pts = []
                i, j = i0, j0
                while 0 <= i <= nx and 0 <= j <= ny:
                    pts.append(index[i, j])
                    i, j = i + di, j + dj
                if len(pts) >= 2:
                    out.append(np.array(pts))
    return out


def _border_loop(index: np.ndarray, nx: int, ny: int) -> np.ndarray:
    """Perimeter nodes counter-clockwise from the lower-left corner."""
    ring = ([(i, 0) for i in range(nx + 1)] + [(nx, j) for j in range(1, ny + 1)]
            + [(i, ny) for i in range(nx - 1, -1, -1)] + [(0, j) for j in range(ny - 1, 0, -1)])
    return np.array([index[i, j] for i, j in ring if index[i, j] >= 0])


PATTERN = NetPattern("diamond", diamond_net, diamond_factor, strand_law, strand_force,
                     span, diamond_nodes, lockup=lockup_strain, mesh_name="mesh diagonal",
                     check_mesh=any_mesh, panel_test=True)
