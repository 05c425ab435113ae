"""Linear solves of a Newton step, (J + mu D) x = b, on the net's fixed pattern.

J is symmetric except for the hydrostatic follower term (the load on a node falls as the node
rises: a (flow, z) entry with no (z, flow) partner). Backends, each optional and imported
lazily (the `fast` extra), in the order `choose_backend` prefers them:

- "pardiso" (MKL PARDISO via `pypardiso`, nets of PARDISO_MIN_DOFS unknowns and more): a
  supernodal LU of A itself; its fill-reducing analysis runs once per net, every later step
  only refactorizes numerically;
- "ldl" (`qdldl`): a sparse LDL^T of the symmetric part S = (A + A^T) / 2, ordering computed
  once per net, then GMRES on A preconditioned by S^-1 (a few iterations: the follower term
  is a small part of A);
- "lu": scipy's SuperLU on A (always there; also the reference path's solver).

Every result is checked against A (backward error LINEAR_RTOL, or the inexact-Newton
forcing); GMRES preconditioned by the factorization repairs a result that misses it, and
SuperLU on A is the last resort. The answer is always that of A.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
import scipy.sparse.linalg as spla

from solver.pattern import Pattern

if TYPE_CHECKING:
    import scipy.sparse as sp

LINEAR_RTOL = 1e-13  # backward error a solve must reach: |b - A x| <= tol (|A| |x| + |b|)
GMRES_RTOL = 1e-14  # GMRES stops at this relative 2-norm residual at the latest
GMRES_RESTART = 30  # GMRES iterations (one restart cycle) before falling back to SuperLU
PARDISO_MIN_DOFS = 100_000  # from here on PARDISO's supernodal LU beats qdldl's LDL^T
# (simple-pinned at 1e-6, 2 cores: even at 57k unknowns, 0.9 s against 2.5 s CPU per
# factorization at 226k; its import and threads cost more than they save on small nets)


def ldl_available() -> bool:
    """True when the optional sparse LDL^T (`qdldl`) imports."""
    try:
        import qdldl  # noqa: F401
    except ImportError:
        return False
    return True


def _mkl_hint() -> None:
    """Point pypardiso at MKL's runtime when it sits in the environment's lib folder: without
    the hint it searches the whole environment tree at import (seconds)."""
    import glob
    import os
    import sys

    if "PYPARDISO_MKL_RT" not in os.environ:
        found = sorted(glob.glob(os.path.join(sys.prefix, "lib", "libmkl_rt.so*")), key=len)
        if found:
            os.environ["PYPARDISO_MKL_RT"] = found[0]


def pardiso_available() -> bool:
    """True when the optional MKL PARDISO wrapper (`pypardiso`) imports."""
    try:
        _mkl_hint()
        import pypardiso  # noqa: F401
    except (ImportError, OSError):
        return False
    return True


def choose_backend(size: int) -> str:
    """The fastest installed backend for a system of `size` unknowns."""
    if size >= PARDISO_MIN_DOFS and pardiso_available():
        return "pardiso"
    return "ldl" if ldl_available() else "lu"


class Pardiso:
    """One PARDISO instance per net: symbolic analysis once, numeric refactorizations after."""

    def __init__(self) -> None:
        import pypardiso

        self.solver = pypardiso.PyPardisoSolver(mtype=11)  # real, non-symmetric
        self.analysed = False
        self.A = None

    def factor(self, A: sp.csr_matrix) -> None:
        zero = np.zeros(A.shape[0])
        if not self.analysed:
            self.solver.set_phase(11)
            self.solver._call_pardiso(A, zero)  # the documented direct call (pypardiso)
            self.analysed = True
        self.solver.set_phase(22)
        self.solver._call_pardiso(A, zero)
        self.A = A

    def solve(self, b: np.ndarray) -> np.ndarray:
        self.solver.set_phase(33)
        return self.solver._call_pardiso(self.A, np.asfortranarray(b))


class Factorization:
    """One factorization of A = J + mu D; `solve` returns None when A is singular.

    backend "pardiso", "ldl" or "lu" (see the module docstring); `handle`: the backend's
    object from an earlier factorization of the same net (a qdldl solver, a Pardiso), reused
    so the ordering is not computed again.
    """

    def __init__(self, pattern: Pattern, data: np.ndarray, backend: str, handle=None) -> None:
        self.pattern, self.A, self.backend = pattern, pattern.csr(data), backend
        self.handle: Any = None  # the backend's object (qdldl.Solver, Pardiso)
        self.direct: Callable[[np.ndarray], np.ndarray] | None = None  # its solve
        self.symmetric = False
        self.lu: Any = None  # scipy's SuperLU, when it is needed
        self.ok = True
        try:
            if backend == "ldl":
                self._factor_ldl(data, handle)
            elif backend == "pardiso":
                handle = handle if handle is not None else Pardiso()
                handle.factor(self.A)
                self.handle, self.direct = handle, handle.solve
        except Exception:  # noqa: BLE001 - a zero pivot or a solver error: SuperLU decides
            self.handle, self.direct = None, None
        if self.direct is None:
            self._factor_lu()

    def _factor_ldl(self, data: np.ndarray, handle) -> None:
        upper = self.pattern.symmetric_upper(data)
        if handle is None:
            import qdldl

            handle = qdldl.Solver(upper, upper=True)
        else:
            handle.update(upper, upper=True)
        self.handle, self.direct, self.symmetric = handle, handle.solve, True

    def _factor_lu(self) -> None:
        try:
            with np.errstate(all="ignore"):
                self.lu = spla.splu(self.A.tocsc())
        except RuntimeError:  # exactly singular
            self.ok = False

    def solve(self, b: np.ndarray, forcing: float = 0.0) -> np.ndarray | None:
        """A^-1 b to a backward error of LINEAR_RTOL, or (inexact Newton) to a residual
        max |b - A x| <= forcing max |b|; None when A is singular."""
        if self.direct is not None:
            x = self._refined(b, forcing)
            if x is not None:
                return x
            if self.lu is None:
                self._factor_lu()
        if not self.ok:
            return None
        with np.errstate(all="ignore"):
            x = self.lu.solve(b)
        return x if np.all(np.isfinite(x)) else None

    def symmetric_solve(self, b: np.ndarray) -> np.ndarray | None:
        """S^-1 b alone (a direction on the symmetric model), or None without an LDL^T."""
        if not self.symmetric or self.direct is None:
            return None
        with np.errstate(all="ignore"):
            x = self.direct(b)
        return x if np.all(np.isfinite(x)) else None

    def _refined(self, b: np.ndarray, forcing: float) -> np.ndarray | None:
        """The direct solve, then GMRES on A preconditioned by it when that misses the
        target (the follower term, with an LDL^T of S); None unless the target is met."""
        a_norm = float(abs(self.A).sum(axis=1).max()) if self.A.nnz else 0.0
        b_norm = float(np.abs(b).max()) if b.size else 0.0

        def good(x: np.ndarray) -> bool:
            if not np.all(np.isfinite(x)):
                return False
            res = b - self.A @ x
            if float(np.abs(res).max()) <= forcing * b_norm:
                return True
            return float(np.abs(res).max()) <= LINEAR_RTOL * (a_norm * float(np.abs(x).max())
                                                              + b_norm)

        direct = self.direct
        if direct is None:
            return None
        try:
            with np.errstate(all="ignore"):
                x = direct(b)
                if good(x):
                    return x
                if not np.all(np.isfinite(x)):
                    return None
                target = max(forcing * b_norm, GMRES_RTOL * float(np.linalg.norm(b)))
                x = gmres(self.A, direct, b, x, target, GMRES_RESTART)
        except Exception:  # noqa: BLE001 - a failing backend: SuperLU decides
            return None
        return x if good(x) else None


def gmres(A: sp.csr_matrix, precondition: Callable[[np.ndarray], np.ndarray], b: np.ndarray,
          x0: np.ndarray, target: float, m: int) -> np.ndarray:
    """One cycle of right-preconditioned GMRES(m): x0 + M^-1 V y minimising |b - A x|_2 over
    the Krylov space of A M^-1, stopped when |b - A x|_2 <= target (classical Gram-Schmidt,
    twice; least squares on the small Hessenberg matrix)."""
    r0 = b - A @ x0
    beta = float(np.linalg.norm(r0))
    if beta <= target or beta == 0.0:
        return x0
    V = np.zeros((m + 1, len(b)))
    Z = np.zeros((m, len(b)))
    H = np.zeros((m + 1, m))
    V[0] = r0 / beta
    e1 = np.zeros(m + 1)
    e1[0] = beta
    y: np.ndarray = np.zeros(0)
    for k in range(m):
        Z[k] = precondition(V[k])
        w = A @ Z[k]
        for _ in range(2):
            h = V[: k + 1] @ w
            w -= h @ V[: k + 1]
            H[: k + 1, k] += h
        H[k + 1, k] = float(np.linalg.norm(w))
        y, *_ = np.linalg.lstsq(H[: k + 2, : k + 1], e1[: k + 2], rcond=None)
        res = float(np.linalg.norm(H[: k + 2, : k + 1] @ y - e1[: k + 2]))
        if res <= target or H[k + 1, k] == 0.0:
            break
        V[k + 1] = w / H[k + 1, k]
    return x0 + y @ Z[: len(y)]
