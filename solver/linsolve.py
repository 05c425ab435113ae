"""Linear solves of a Newton step, (J + mu D) x = b, on the net's fixed pattern.

J is symmetric except for the hydrostatic follower term (the load on a node falls as the node
rises: a (flow, z) entry with no (z, flow) partner). Backends, each optional and imported
lazily (the `fast` extra), in the order `choose_backend` prefers them:

- "pardiso" (MKL PARDISO via `pypardiso`, nets of PARDISO_MIN_DOFS unknowns and more): a
  supernodal Cholesky (LDL^T once S proves indefinite) of the symmetric part
  S = (A + A^T) / 2; its fill-reducing analysis runs once per net, every later step only
  refactorizes numerically;
- "ldl" (`qdldl`): a sparse LDL^T of S, ordering computed once per net;
- "lu": scipy's SuperLU on A (always there; also the reference path's solver).

With "pardiso" and "ldl", GMRES on A preconditioned by S^-1 takes care of the follower term
(a few iterations: it is a small part of A).

Every result is checked against A (backward error LINEAR_RTOL, or the inexact-Newton
forcing); GMRES preconditioned by the factorization repairs a result that misses it, and
SuperLU on A is the last resort. The answer is always that of A.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from solver.pattern import Pattern

LINEAR_RTOL = 1e-13  # backward error a solve must reach: |b - A x| <= tol (|A| |x| + |b|)
GMRES_RTOL = 1e-14  # GMRES stops at this relative 2-norm residual at the latest
GMRES_RESTART = 30  # GMRES iterations (one restart cycle) before falling back to SuperLU
PARDISO_MIN_DOFS = 6_500  # from here on PARDISO's supernodal Cholesky of S beats qdldl's
# LDL^T (simple-pinned, 1 thread, CPU per numeric factorization: 3.4k unknowns 4 / 5 ms, 14k
# 21 / 64 ms, 57k 76 / 690 ms; whole solve at tol 1e-6: 5.3k 0.29 / 0.21 s, 7.7k 0.37 /
# 0.48 s, 14k 0.87 / 1.26 s: PARDISO's solves and set-up cost more on small nets)
PARDISO_IPARM = {1: 1, 2: 2, 8: 0, 10: 13, 11: 0, 13: 0, 21: 1}  # MKL's iparm (1-based):
# own settings, METIS ordering, no refinement, pivot perturbation 1e-13, no scaling or
# matching, Bunch-Kaufman pivots (mtype -2); everything else MKL's zero default


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
    """One MKL PARDISO instance per net, on the symmetric part S: its fill-reducing analysis
    (METIS nested dissection) runs once, every later step only refactorizes numerically.

    A Cholesky factorization (mtype 2) while S is positive definite; from the first
    non-positive pivot on, Bunch-Kaufman LDL^T (mtype -2, pivots perturbed at 1e-13 of the
    norm, analysed again once). No iterative refinement inside PARDISO (iparm 8 = 0) and no
    scaling or matching (iparm 11, 13 = 0: S is symmetric): `Factorization` checks every
    result against A and repairs it with GMRES.
    """

    def __init__(self) -> None:
        _mkl_hint()
        import pypardiso

        self.error = pypardiso.pardiso_wrapper.PyPardisoError
        self.solver = self._solver(2)
        self.analysed = False
        self.S = None
        self.empty = sp.csr_matrix((0, 0))  # what MKL's release phase is called with

    @staticmethod
    def _solver(mtype: int):
        import pypardiso

        solver = pypardiso.PyPardisoSolver(mtype=mtype)
        for k, value in PARDISO_IPARM.items():
            solver.iparm[k - 1] = value  # the 1-based numbering of MKL's documentation
        return solver

    def _call(self, phase: int, rhs: np.ndarray) -> np.ndarray:
        self.solver.set_phase(phase)
        return self.solver._call_pardiso(self.S, rhs)  # the documented direct call (pypardiso)

    def factor(self, S: sp.csr_matrix) -> None:
        """Factorize S, given as the CSR upper triangle of the same pattern at every call."""
        self.S = S
        zero = np.zeros(S.shape[0])
        try:
            if not self.analysed:
                self._call(11, zero)
                self.analysed = True
            self._call(22, zero)
        except self.error:
            if self.solver.mtype != 2:
                raise
            self.free()
            self.solver, self.analysed = self._solver(-2), True
            self._call(11, zero)
            self._call(22, zero)

    def solve(self, b: np.ndarray) -> np.ndarray:
        return self._call(33, np.asfortranarray(b))

    def free(self) -> None:
        """Release MKL's memory of this instance (factors and analysis)."""
        with contextlib.suppress(self.error):  # nothing allocated yet
            self.solver.set_phase(-1)
            self.solver._call_pardiso(self.empty, np.zeros(0))

    def __del__(self) -> None:
        with contextlib.suppress(Exception):  # at interpreter exit, modules may be gone
            self.free()


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
        self.a_norm: float | None = None  # max row sum of |A|, once a solve needs it
        self.last: tuple[np.ndarray, np.ndarray] | None = None  # (b, S^-1 b) of the last solve
        try:
            if backend == "ldl":
                self._factor_ldl(data, handle)
            elif backend == "pardiso":
                handle = handle if handle is not None else Pardiso()
                handle.factor(pattern.symmetric_upper_csr(data))
                self.handle, self.direct, self.symmetric = handle, handle.solve, True
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
        """S^-1 b alone (a direction on the symmetric model), or None without an LDL^T.
        The last `solve` already computed it when `b` is its right-hand side: then no new
        solve (and no reliance on the backend's object still holding this factorization)."""
        if not self.symmetric or self.direct is None:
            return None
        if self.last is not None and self.last[0] is b:
            x = self.last[1].copy()
        else:
            with np.errstate(all="ignore"):
                x = self.direct(b)
        return x if np.all(np.isfinite(x)) else None

    def _refined(self, b: np.ndarray, forcing: float) -> np.ndarray | None:
        """The direct solve, then GMRES on A preconditioned by it when that misses the
        target (the follower term, with an LDL^T of S); None unless the target is met."""
        if self.a_norm is None:
            self.a_norm = row_sum_norm(self.A)
        direct = self.direct
        if direct is None:
            return None
        try:
            with np.errstate(all="ignore"):
                x = direct(b)
                self.last = (b, x.copy())
                return refine(self.A, direct, b, x, forcing, self.a_norm)
        except Exception:  # noqa: BLE001 - a failing backend: SuperLU decides
            return None


def row_sum_norm(A: sp.csr_matrix) -> float:
    """max row sum of |A| (the infinity norm of the backward-error test), summed over A's
    stored entries row by row (a tenth of the time of abs(A).sum(axis=1))."""
    if not A.nnz:
        return 0.0
    starts = A.indptr[:-1][np.diff(A.indptr) > 0]  # the rows that have entries
    return float(np.add.reduceat(np.abs(A.data), starts).max())


def meets(A: sp.csr_matrix, b: np.ndarray, x: np.ndarray, forcing: float, a_norm: float
          ) -> bool:
    """x solves A x = b to a backward error of LINEAR_RTOL, or (inexact Newton) to a
    residual max |b - A x| <= forcing max |b|."""
    if not np.all(np.isfinite(x)):
        return False
    b_norm = float(np.abs(b).max()) if b.size else 0.0
    res = float(np.abs(b - A @ x).max()) if b.size else 0.0
    return res <= forcing * b_norm or res <= LINEAR_RTOL * (a_norm * float(np.abs(x).max())
                                                            + b_norm)


def refine(A: sp.csr_matrix, precondition: Callable[[np.ndarray], np.ndarray], b: np.ndarray,
           x: np.ndarray, forcing: float, a_norm: float) -> np.ndarray | None:
    """x when it `meets` the target, else GMRES on A preconditioned by `precondition` from
    x; None unless the result meets it."""
    if meets(A, b, x, forcing, a_norm):
        return x
    if not np.all(np.isfinite(x)):
        return None
    b_norm = float(np.abs(b).max()) if b.size else 0.0
    target = max(forcing * b_norm, GMRES_RTOL * float(np.linalg.norm(b)))
    x = gmres(A, precondition, b, x, target, GMRES_RESTART)
    return x if meets(A, b, x, forcing, a_norm) else None


def gmres(A: sp.csr_matrix, precondition: Callable[[np.ndarray], np.ndarray], b: np.ndarray,
          x0: np.ndarray, target: float, m: int) -> np.ndarray:
    """One cycle of right-preconditioned GMRES(m): x0 + M^-1 V y minimising |b - A x|_2 over
    the Krylov space of A M^-1, stopped when |b - A x|_2 <= target (classical Gram-Schmidt,
    twice; the Hessenberg matrix reduced by Givens rotations as it grows, so the residual
    norm is known at every step without a least-squares solve)."""
    r0 = b - A @ x0
    beta = float(np.linalg.norm(r0))
    if beta <= target or beta == 0.0:
        return x0
    V, Z = np.empty((m + 1, len(b))), np.empty((m, len(b)))  # the Krylov basis, M^-1 V
    V[0] = r0 / beta
    R = np.zeros((m, m))  # the rotated (upper triangular) Hessenberg matrix
    cs, sn = np.zeros(m), np.zeros(m)
    g = np.zeros(m + 1)
    g[0] = beta
    k = 0
    for k in range(m):
        Z[k] = precondition(V[k])
        w = A @ Z[k]
        Vk = V[: k + 1]
        h = np.zeros(k + 2)
        for _ in range(2):
            c = Vk @ w
            w = w - c @ Vk
            h[: k + 1] += c
        h[k + 1] = float(np.linalg.norm(w))
        for i in range(k):  # the earlier rotations, then this column's own
            h[i], h[i + 1] = cs[i] * h[i] + sn[i] * h[i + 1], -sn[i] * h[i] + cs[i] * h[i + 1]
        rho = float(np.hypot(h[k], h[k + 1]))
        cs[k], sn[k] = (h[k] / rho, h[k + 1] / rho) if rho > 0 else (1.0, 0.0)
        R[: k + 1, k] = h[: k + 1]
        R[k, k] = rho
        g[k + 1] = -sn[k] * g[k]
        g[k] = cs[k] * g[k]
        if abs(g[k + 1]) <= target or h[k + 1] == 0.0 or rho == 0.0:
            break
        V[k + 1] = w / h[k + 1]
    n = k + 1
    diag = np.abs(np.diag(R[:n, :n]))
    while n and diag[n - 1] == 0.0:  # a breakdown column: solve on the ones before it
        n -= 1
    if not n:
        return x0
    y = np.linalg.solve(np.triu(R[:n, :n]), g[:n])
    return x0 + y @ Z[:n]
