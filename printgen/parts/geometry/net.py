"""Diamond-net centre-line graph in the print plane (mm), shared by the solver scenes, the
meshes and the toolpaths.

Lattice: strand crossings at (i * a/2, j * b/2) with i + j even, where a is the mesh diagonal
along x (across the barrier) and b the diagonal along y (up the barrier). Strands are straight
lines of slope +b/a (family +1) and -b/a (family -1) from border to border; a border strand
(family 0) runs around the perimeter through every boundary node and the four corners. The
mesh diagonals are kept exact: the panel size is rounded to whole half-diagonals and the
difference is reported in `size_error_mm`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from printgen.errors import GeometryError

MIN_HALF_CELLS = 2  # fewer half-meshes across than this is not a net


@dataclass(frozen=True)
class NetGraph:
    """Centre lines of a diamond net.

    nodes_mm : (n, 2) float, mm; x across, y up; origin at the lower-left corner
    segments : (m, 2) int, node indices of straight pieces between neighbouring nodes
    family : (m,) int, +1 / -1 diagonal strand families, 0 border
    strands : list of (k,) int arrays, each a straight diagonal strand, border to border
    border : (p,) int, closed perimeter loop of node indices (first node not repeated)
    mesh_mm : (a, b) diagonals; half_cells : (nx, ny) half-diagonals across and up
    """

    nodes_mm: np.ndarray
    segments: np.ndarray
    family: np.ndarray
    strands: list[np.ndarray]
    border: np.ndarray
    mesh_mm: tuple[float, float]
    half_cells: tuple[int, int]

    @property
    def size_mm(self) -> tuple[float, float]:
        return float(self.nodes_mm[:, 0].max()), float(self.nodes_mm[:, 1].max())

    @property
    def on_border(self) -> np.ndarray:
        mask = np.zeros(len(self.nodes_mm), dtype=bool)
        mask[self.border] = True
        return mask

    def segment_lengths_mm(self) -> np.ndarray:
        d = self.nodes_mm[self.segments[:, 1]] - self.nodes_mm[self.segments[:, 0]]
        return np.hypot(d[:, 0], d[:, 1])


def diamond_net(width_mm: float, height_mm: float, mesh_x_mm: float, mesh_y_mm: float) -> NetGraph:
    """Build the diamond-net graph of a panel about `width_mm` x `height_mm`.

    The panel is nx = round(2 W / a) half-diagonals wide and ny = round(2 H / b) high.
    """
    for label, v in (("width", width_mm), ("height", height_mm),
                     ("mesh_x", mesh_x_mm), ("mesh_y", mesh_y_mm)):
        if not np.isfinite(v) or v <= 0:
            raise GeometryError(f"net {label} = {v!r} mm must be a positive finite length")
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
