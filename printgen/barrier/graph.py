"""A net's centre-line graph in the print plane (mm): what every pattern builds, and what the
solver scenes, the meshes and the toolpaths read."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from printgen.errors import GeometryError


@dataclass(frozen=True)
class NetGraph:
    """Centre lines of a net.

    nodes_mm : (n, 2) float, mm; x across, y up; origin at the lower-left corner
    segments : (m, 2) int, node indices of straight pieces between neighbouring nodes
    family : (m,) int, +1 / -1 strand families (the diamond's diagonals; the square's strands
      up and across), 0 border
    strands : list of (k,) int arrays, each a straight strand, border to border
    border : (p,) int, closed perimeter loop of node indices (first node not repeated)
    mesh_mm : (a, b) the mesh across and up (the diamond's diagonals, the square's sides);
    half_cells : (nx, ny) lattice steps across and up (the diamond's half-diagonals, the
      square's sides)
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


def check_lengths(**lengths_mm: float) -> None:
    """GeometryError unless every length is positive and finite."""
    for label, v in lengths_mm.items():
        if not np.isfinite(v) or v <= 0:
            raise GeometryError(f"net {label} = {v!r} mm must be a positive finite length")
