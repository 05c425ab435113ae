"""The node rows the mid-height sensor is read from (`printgen.scene.scenes` states the
physics): the one or two rows strictly inside the net that bracket half its height, weighted by
linear interpolation in z, and each row's wire carried from the left edge to the right edge."""

from __future__ import annotations

import numpy as np

from printgen.errors import GeometryError


def mid_levels(x: np.ndarray, z: np.ndarray, w: float, h: float, tol: float
               ) -> list[tuple[float, float]]:
    """(height m, weight) of the one or two node rows that bracket mid-height h/2, weighted by
    linear interpolation in z (`printgen.scene.scenes`). Rows strictly between the bottom and
    the top rows only; rows that reach both lateral edges (a sensor wire is anchored at the
    edge) when two of them bracket h/2, else any rows (`to_edges` carries their wires to the
    edges)."""
    levels = np.unique(np.round(z / tol)) * tol
    inner = levels[(levels > 2 * tol) & (levels < h - 2 * tol)]
    if not inner.size:
        raise GeometryError(f"the net has no node row between its bottom and top edges "
                            f"({h:.4g} m high): no row for the mid-height sensor; use a "
                            "smaller mesh")
    spans = np.array([lv for lv in inner if np.any((np.abs(z - lv) < 2 * tol) & (x < tol))
                      and np.any((np.abs(z - lv) < 2 * tol) & (x > w - tol))])
    mid = h / 2
    for pool in (spans, inner):
        below, above = pool[pool <= mid + 2 * tol], pool[pool >= mid - 2 * tol]
        if below.size and above.size:
            lo, hi = (float(z[np.argmin(np.abs(z - lv))]) for lv in (below.max(), above.min()))
            if hi - lo < 4 * tol:  # a row at mid-height
                return [(lo, 1.0)]
            t = (mid - lo) / (hi - lo)
            return [(lo, 1.0 - t), (hi, t)]
    return [(float(inner[np.argmin(np.abs(inner - mid))]), 1.0)]


def to_edges(row: np.ndarray, left: np.ndarray, right: np.ndarray, z: np.ndarray
              ) -> np.ndarray:
    """A row's wire nodes from the left edge to the right edge: a row that stops short of an
    edge (a diamond's rows alternate) is continued to the edge node nearest its height."""
    first = [] if row[0] in left else [int(left[np.argmin(np.abs(z[left] - z[row[0]]))])]
    last = [] if row[-1] in right else [int(right[np.argmin(np.abs(z[right] - z[row[-1]]))])]
    return np.concatenate([first, row, last]).astype(int)
