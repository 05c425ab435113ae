"""Tension-only piecewise-linear force-strain laws, shared by materials, targets and selection."""

from __future__ import annotations

import numpy as np


def piecewise_linear(eps: np.ndarray | float, knees: tuple[float, ...] | list[float],
                     slopes: tuple[float, ...] | list[float]) -> np.ndarray:
    """Sum over segments of slope_i times the part of eps in segment i; zero for eps <= 0.

    knees : (k,) increasing strains; slopes : (k+1,) tangent stiffness per unit strain.
    """
    e = np.maximum(np.asarray(eps, dtype=float), 0.0)
    lo = np.array([0.0, *knees])
    width = np.append(np.diff(lo), np.inf)
    return np.clip(e[..., None] - lo, 0.0, width) @ np.asarray(slopes, dtype=float)
