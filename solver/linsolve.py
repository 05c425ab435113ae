"""Linear solves of a Newton step, (J + mu D) x = b, on the net's fixed pattern.

J is symmetric except for the hydrostatic follower term (the load on a node falls as the node
rises: a (flow, z) entry with no (z, flow) partner). The fast backend factorizes the
symmetric part S = (A + A^T) / 2 by a sparse LDL^T (`qdldl`, optional: the `fast` extra; its
fill-reducing ordering is computed once per net and reused by every refactorization), then
recovers the solution of the true, non-symmetric A by GMRES preconditioned with S^-1 (a few
iterations: the follower term is a small part of A). The result is checked: if it does not
reach LINEAR_RTOL (the follower term too strong, or S indefinite), the same system is solved
by SuperLU on A. The
answer is always that of A; symmetrizing only chooses how it is computed.
Without `qdldl` every solve is SuperLU's (scipy), which is also the reference backend.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse.linalg as spla

from solver.pattern import Pattern

LINEAR_RTOL = 1e-13  # backward error a solve must reach: |b - A x| <= tol (|A| |x| + |b|)
GMRES_RTOL = 1e-14  # GMRES stops at this relative 2-norm residual at the latest
GMRES_RESTART = 30  # GMRES iterations (one restart cycle) before falling back to SuperLU


def ldl_available() -> bool:
    """True when the optional sparse LDL^T (`qdldl`) imports."""
    try:
        import qdldl  # noqa: F401
    except ImportError:
        return False
    return True


class Factorization:
    """One factorization of A = J + mu D; `solve` returns None when A is singular.

    backend "ldl" (LDL^T of the symmetric part + GMRES, SuperLU when that fails) or "lu"
    (SuperLU); `ldl`: the qdldl solver of an earlier factorization, refactorized in place.
    """

    def __init__(self, pattern: Pattern, data: np.ndarray, backend: str, ldl=None) -> None:
        self.pattern, self.A, self.backend, self.ldl = pattern, pattern.csr(data), backend, None
        self.lu = None
        self.ok = True
        if backend == "ldl":
            try:
                upper = pattern.symmetric_upper(data)
                if ldl is None:
                    import qdldl

                    ldl = qdldl.Solver(upper, upper=True)
                else:
                    ldl.update(upper, upper=True)
                self.ldl = ldl
            except (ValueError, RuntimeError):  # a zero pivot: S singular
                self.ldl = None
        if self.ldl is None:
            self._factor_lu()

    def _factor_lu(self) -> None:
        try:
            with np.errstate(all="ignore"):
                self.lu = spla.splu(self.A.tocsc())
        except RuntimeError:  # exactly singular
            self.ok = False

    def solve(self, b: np.ndarray, forcing: float = 0.0) -> np.ndarray | None:
        """A^-1 b to a backward error of LINEAR_RTOL, or (inexact Newton) to a residual
        max |b - A x| <= forcing max |b|; None when A is singular."""
        if self.ldl is not None:
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
        if self.ldl is None:
            return None
        with np.errstate(all="ignore"):
            x = self.ldl.solve(b)
        return x if np.all(np.isfinite(x)) else None

    def _refined(self, b: np.ndarray, forcing: float) -> np.ndarray | None:
        """S^-1 b, then GMRES on A preconditioned by S^-1 when the follower term matters;
        None unless the backward error reaches LINEAR_RTOL."""
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

        with np.errstate(all="ignore"):
            x = self.ldl.solve(b)
            if good(x):
                return x
            if not np.all(np.isfinite(x)):
                return None
            target = max(forcing * b_norm, GMRES_RTOL * float(np.linalg.norm(b)))
            x = gmres(self.A, self.ldl.solve, b, x, target, GMRES_RESTART)
        return x if good(x) else None


def gmres(A, precondition, b: np.ndarray, x0: np.ndarray, target: float, m: int) -> np.ndarray:
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
    y = np.zeros(0)
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
