"""What a solve returns: the state, and whether (and how well) it converged."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


class SolverError(RuntimeError):
    """A strict solve did not converge; the message says why."""


@dataclass(frozen=True)
class Result:
    """positions, displacements : (n, 3) m; strains, tensions : (m,) of the strands (N);
    slack : (m,) bool, strands carrying no force; cable_strains, cable_tensions : (c,) of the
    sliding cables; residual : max out-of-balance force on a free node (N); load_norm : max
    applied force (N); converged with `reason`; iterations (Newton and chord steps);
    seconds; level of a load path; factorizations of the tangent (the main cost); backend: the
    linear solver of the tangent ("ldl" qdldl, "pardiso" MKL PARDISO, "lu" SuperLU: see
    solver.linsolve)."""

    positions: np.ndarray
    displacements: np.ndarray
    strains: np.ndarray
    tensions: np.ndarray
    slack: np.ndarray
    cable_strains: np.ndarray
    cable_tensions: np.ndarray
    residual: float
    load_norm: float
    iterations: int
    converged: bool
    reason: str
    seconds: float
    level: float | None = None
    factorizations: int = 0
    backend: str = "lu"
