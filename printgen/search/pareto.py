"""Pareto sets: the candidates no other candidate beats on every objective (all minimised)."""

from __future__ import annotations

import numpy as np


def dominates(a: np.ndarray, b: np.ndarray) -> bool:
    """True when `a` is no worse than `b` on every objective and better on one."""
    return bool(np.all(a <= b) and np.any(a < b))


def pareto_mask(values: np.ndarray) -> np.ndarray:
    """(n,) bool: rows of `values` ((n, k), minimised) that no other row dominates.

    Rows are visited best-first on the first objective (then the others), so a row can only
    be dominated by rows visited before it or equal to it; equal rows are all kept.
    """
    v = np.asarray(values, dtype=float)
    if v.ndim != 2:
        raise ValueError(f"objectives must be an (n, k) array, got shape {v.shape}")
    if not np.all(np.isfinite(v)):
        raise ValueError("objectives must be finite (leave out candidates without a value)")
    order = np.lexsort(v.T[::-1])
    keep = np.zeros(len(v), dtype=bool)
    front: list[int] = []
    for i in order:
        row = v[i]
        if front:
            f = v[front]
            if np.any(np.all(f <= row, axis=1) & np.any(f < row, axis=1)):
                continue
        front.append(int(i))
        keep[i] = True
    return keep
