"""Linear solves of a Newton step, (J + mu D) x = b, on the net's fixed pattern.

J is symmetric except for the hydrostatic follower term (the load on a node falls as the node
rises: a (flow, z) entry with no (z, flow) partner). Backends, each optional and imported
lazily (the `fast` extra), in the order `choose_backend` prefers them:

- "pardiso" (MKL PARDISO via `pypardiso`, nets of PARDISO_MIN_DOFS unknowns and more): a
  supernodal Cholesky (LDL^T once S proves indefinite) of the symmetric part
  S = (A + A^T) / 2; its fill-reducing analysis runs once per net, every later step only
  refactorizes numerically;
- "cholmod" (CHOLMOD's supernodal Cholesky of S through `cvxopt`, nets of CHOLMOD_MIN_DOFS
  unknowns and more; its wheels carry their own SuiteSparse and BLAS): its AMD ordering
  and symbolic analysis once per net, then numeric factorizations on dense supernodal
  blocks, a fifth of qdldl's time at 57k unknowns and a twelfth at 228k; on the first
  factorization that finds S not positive definite it turns to "ldl" for the rest of the net;
- "ldl" (`qdldl`): a sparse LDL^T of S, ordering computed once per net; on a net that is
  factorized more than LDL_TO_PARDISO times (a load path) and has LDL_PARDISO_MIN_DOFS
  unknowns or more, the later factorizations are PARDISO's when it is installed (one thread;
  about half of qdldl's numeric factorization, an analysis costing about two of qdldl's);
- "lu": scipy's SuperLU on A (always there; also the reference path's solver).

With "pardiso", "cholmod" and "ldl", GMRES on A preconditioned by S^-1 takes care of the
follower term (a few iterations: it is a small part of A).

Every result is checked against A (backward error LINEAR_RTOL, or the inexact-Newton
forcing); GMRES preconditioned by the factorization repairs a result that misses it, and
SuperLU on A is the last resort. The answer is always that of A.
"""

from __future__ import annotations

import contextlib
import ctypes
import threading
import time
from collections.abc import Callable
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .pattern import Pattern

LINEAR_RTOL = 1e-13  # backward error a solve must reach: |b - A x| <= tol (|A| |x| + |b|)
GMRES_RTOL = 1e-14  # GMRES stops at this relative 2-norm residual at the latest
GMRES_RESTART = 30  # GMRES iterations (one restart cycle) before falling back to SuperLU
PARDISO_MIN_DOFS = 5_000  # from here on PARDISO's Cholesky of S beats qdldl's LDL^T (whole
# solves of the simple scene, 1 thread: benchmarks/measurements.md#linsolve-pardiso-min-dofs)
PARDISO_IPARM = {1: 1, 2: 0, 8: 0, 10: 13, 11: 0, 13: 0, 21: 1}  # MKL's iparm (1-based):
# own settings, minimum-degree ordering, no refinement, pivot perturbation 1e-13, no scaling
# or matching, Bunch-Kaufman pivots (mtype -2); everything else MKL's zero default.
# Minimum degree (iparm 2 = 0), not METIS nested dissection (2), on these grid nets, 1 thread:
# fewer flops in the factor and half the analysis; the other settings tried (parallel METIS,
# two-level factorization, VBSR, low-rank update, single precision) were no faster or lost
# digits (benchmarks/measurements.md#linsolve-pardiso-ordering)

LDL_TO_PARDISO = 8  # a small net's first 8 factorizations are qdldl's, the later PARDISO's:
# a single solve (a few factorizations) keeps qdldl and loads no MKL, a load path (hundreds)
# pays PARDISO's import and analysis once and factorizes faster after
# (benchmarks/measurements.md#linsolve-ldl-to-pardiso)
LDL_PARDISO_MIN_DOFS = 2000  # below, a factorization costs too little for the switch to pay
# back MKL's import (benchmarks/measurements.md#linsolve-ldl-pardiso-min-dofs)
LDL_PARDISO_THREADS = 1  # MKL threads of those factorizations and solves: MKL's default (one
# per core) costs ten times the CPU per factorization or more
# (benchmarks/measurements.md#linsolve-threads)

CHOLMOD_MIN_DOFS = 4_000  # from here on CHOLMOD's supernodal Cholesky beats qdldl's LDL^T:
# whole solves of simple-pinned at tol 1e-6, 1 thread, CPU: 3.4k unknowns qdldl 0.035 s,
# CHOLMOD 0.036 s (a tie: the 61 x 21 net stays on qdldl); 7.7k 0.120 against 0.098 s; 57k
# 4.45 against 0.93 s (`python -m benchmarks.bench_solver --backends ldl cholmod`, its
# backend_table). Along a load path the analysis is paid once: a load path of the 1:20
# verification (4.2k unknowns, 23 levels) 1.25 s with qdldl, 0.72 s with CHOLMOD

METIS_MIN_DOFS = 100_000  # from here on CHOLMOD's analysis orders the tangent by METIS's
# nested dissection of the node graph (`pymetis`, when installed) instead of AMD: a numeric
# factorization ~12 % and a solve ~10 % cheaper at 228k unknowns for an ordering of ~0.25 s;
# below, a solve's factorizations save about what the ordering costs
# (benchmarks/measurements.md#linsolve-metis-min-dofs)

PHASES = {11: "analysis", 22: "factorization", 33: "solve"}  # MKL's phases, as Pardiso counts


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


def cholmod_available() -> bool:
    """True when CHOLMOD through `cvxopt` (the `fast` extra) imports."""
    try:
        import cvxopt.cholmod  # noqa: F401
    except ImportError:
        return False
    return True


def metis_available() -> bool:
    """True when METIS's nested dissection (`pymetis`) imports."""
    try:
        import pymetis  # noqa: F401
    except ImportError:
        return False
    return True


def nested_dissection(pattern: Pattern) -> np.ndarray | None:
    """METIS's nested-dissection order of the pattern's free dofs, computed on the node graph
    (`Pattern.node_adjacency`: a ninth of the dof graph's entries, so a ninth of the work)
    and expanded node by node; None without `pymetis` or without two coupled nodes (then
    CHOLMOD's AMD orders the little there is)."""
    try:
        import pymetis
    except ImportError:
        return None
    xadj, adjncy = pattern.node_adjacency()
    if not len(adjncy):
        return None
    if hasattr(pymetis, "CSRAdjacency"):
        perm, _ = pymetis.nested_dissection(adjacency=pymetis.CSRAdjacency(xadj, adjncy))
    else:  # pymetis before 2025 takes the arrays themselves
        perm, _ = pymetis.nested_dissection(xadj=xadj, adjncy=adjncy)
    return pattern.dof_order(np.asarray(perm, dtype=np.intp))


_PARDISO_FAILED: list[bool] = []  # an import of pypardiso failed in this process


def pardiso_available() -> bool:
    """True when the optional MKL PARDISO wrapper (`pypardiso`) imports.

    Asked at every factorization: an import that failed once is not retried (a failing
    import searches sys.path again each time, and the MKL hint globs the environment: a
    series' 572 factorizations paid ~0.1 s CPU for it); one in sys.modules (or set to None
    there, as a test hides it) answers at once."""
    import sys

    if "pypardiso" in sys.modules:
        return sys.modules["pypardiso"] is not None
    if _PARDISO_FAILED:
        return False
    try:
        _mkl_hint()
        import pypardiso  # noqa: F401
    except (ImportError, OSError):
        _PARDISO_FAILED.append(True)
        return False
    return True


def choose_backend(size: int) -> str:
    """The fastest installed backend for a system of `size` unknowns."""
    if size >= PARDISO_MIN_DOFS and pardiso_available():
        return "pardiso"
    if size >= CHOLMOD_MIN_DOFS and cholmod_available():
        return "cholmod"
    return "ldl" if ldl_available() else "lu"


class Pardiso:
    """One MKL PARDISO instance per net, on the symmetric part S: its fill-reducing analysis
    (minimum degree) runs once, every later step only refactorizes numerically.

    A Cholesky factorization (mtype 2) while S is positive definite; from the first
    non-positive pivot on, Bunch-Kaufman LDL^T (mtype -2, pivots perturbed at 1e-13 of the
    norm, analysed again once). No iterative refinement inside PARDISO (iparm 8 = 0) and no
    scaling or matching (iparm 11, 13 = 0: S is symmetric): `Factorization` checks every
    result against A and repairs it with GMRES. MKL is called directly with the pattern's
    1-based int32 index arrays, converted once per net (pypardiso's call converts them at
    every factorization and solve: 2.5 ms a call at 57k unknowns, ~30 calls a solve).
    """

    def __init__(self, threads: int | None = None) -> None:
        _mkl_hint()
        import pypardiso

        self.error = pypardiso.pardiso_wrapper.PyPardisoError
        self.threads = threads  # MKL threads of this instance's calls (None: MKL's setting)
        self.solver = self._solver(2)
        self.analysed = False
        self.S: sp.csr_matrix | None = None  # the factorized matrix (MKL may read it at solves)
        self.ia: np.ndarray | None = None  # S.indptr + 1 as int32
        self.ja: np.ndarray | None = None  # S.indices + 1 as int32
        self.source: tuple | None = None  # the (indptr, indices) arrays they were made from
        self.cpu = dict.fromkeys(PHASES.values(), 0.0)  # CPU seconds (process_time) by phase
        self.calls = dict.fromkeys(PHASES.values(), 0)

    @staticmethod
    def _solver(mtype: int):
        import pypardiso

        solver = pypardiso.PyPardisoSolver(mtype=mtype)
        for k, value in PARDISO_IPARM.items():
            solver.iparm[k - 1] = value  # the 1-based numbering of MKL's documentation
        return solver

    def _index(self, S: sp.csr_matrix) -> None:
        """The 1-based int32 index arrays of S, kept while the pattern stays the same (a new
        pattern is analysed afresh)."""
        ia, ja = self.ia, self.ja
        if self.source is not None and self.source[0] is S.indptr and self.source[1] is S.indices:
            return  # the very arrays of the last call (the pattern's, shared by every step)
        self.source = (S.indptr, S.indices)
        if (ia is not None and ja is not None and len(ia) == len(S.indptr)
                and len(ja) == len(S.indices) and np.array_equal(ia - 1, S.indptr)
                and np.array_equal(ja - 1, S.indices)):
            return
        self.ia = (S.indptr + 1).astype(np.int32)
        self.ja = (S.indices + 1).astype(np.int32)
        self.analysed = False

    def _call(self, phase: int, rhs: np.ndarray, nrhs: int = 1) -> np.ndarray:
        """MKL's pardiso(...) at `phase` on the current S (pypardiso's library handle)."""
        solver, S = self.solver, self.S
        if S is None or self.ia is None or self.ja is None:
            raise self.error(-1)
        data = np.ascontiguousarray(S.data, dtype=np.float64)
        x = np.zeros_like(rhs)
        error = ctypes.c_int32(0)
        t0 = time.process_time()
        i32 = ctypes.POINTER(ctypes.c_int32)
        local = solver.libmkl.MKL_Set_Num_Threads_Local
        previous = local(self.threads) if self.threads is not None else None
        solver._mkl_pardiso(
            solver.pt.ctypes.data_as(ctypes.POINTER(solver._pt_type[0])),
            ctypes.byref(ctypes.c_int32(1)), ctypes.byref(ctypes.c_int32(1)),  # maxfct, mnum
            ctypes.byref(ctypes.c_int32(solver.mtype)), ctypes.byref(ctypes.c_int32(phase)),
            ctypes.byref(ctypes.c_int32(S.shape[0])), data.ctypes.data_as(ctypes.c_void_p),
            self.ia.ctypes.data_as(i32), self.ja.ctypes.data_as(i32),
            solver.perm.ctypes.data_as(i32), ctypes.byref(ctypes.c_int32(nrhs)),
            solver.iparm.ctypes.data_as(i32), ctypes.byref(ctypes.c_int32(0)),  # msglvl
            rhs.ctypes.data_as(ctypes.c_void_p), x.ctypes.data_as(ctypes.c_void_p),
            ctypes.byref(error))
        if previous is not None:
            local(previous)  # this thread's setting as it was (0: MKL's global one)
        name = PHASES.get(phase)
        if name is not None:
            self.cpu[name] += time.process_time() - t0
            self.calls[name] += 1
        if error.value != 0:
            raise self.error(error.value)
        return x

    def factor(self, S: sp.csr_matrix) -> None:
        """Factorize S, given as the CSR upper triangle of the same pattern at every call."""
        self._index(S)
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
            self.S = S
            self._call(11, zero)
            self._call(22, zero)

    def solve(self, b: np.ndarray) -> np.ndarray:
        return self._call(33, np.ascontiguousarray(b, dtype=np.float64))

    def free(self) -> None:
        """Release MKL's memory of this instance (factors and analysis)."""
        if self.S is None:
            return  # nothing allocated yet
        with contextlib.suppress(self.error):
            self._call(-1, np.zeros(self.S.shape[0]))
        self.S = None

    def __del__(self) -> None:
        with contextlib.suppress(Exception):  # at interpreter exit, modules may be gone
            self.free()


class Ldl:
    """The "ldl" backend's object of one net: LDL^T factorizations of S, qdldl's (its AMD
    ordering computed once, later factorizations numeric only) and, once the net has been
    factorized LDL_TO_PARDISO times and has LDL_PARDISO_MIN_DOFS unknowns or more, PARDISO's
    on LDL_PARDISO_THREADS threads when it is installed (its analysis once, then numeric
    factorizations at about half of qdldl's cost). `solve` is the latest factorization's."""

    def __init__(self) -> None:
        self.count = 0  # factorizations so far
        self.qdldl: Any = None
        self.pardiso: Pardiso | None = None
        self.solve: Callable[[np.ndarray], np.ndarray] | None = None

    def factor(self, pattern: Pattern, data: np.ndarray) -> None:
        self.count += 1
        if (self.pardiso is None and self.count > LDL_TO_PARDISO
                and pattern.size >= LDL_PARDISO_MIN_DOFS and pardiso_available()):
            self.pardiso, self.qdldl = Pardiso(threads=LDL_PARDISO_THREADS), None
        if self.pardiso is not None:
            self.pardiso.factor(pattern.symmetric_upper_csr(data))
            self.solve = self.pardiso.solve
            return
        upper = pattern.symmetric_upper(data)
        if self.qdldl is None:
            import qdldl

            self.qdldl = qdldl.Solver(upper, upper=True)
        else:
            self.qdldl.update(upper, upper=True)
        self.solve = self.qdldl.solve


_CHOLMOD_OPTIONS = threading.Lock()  # cvxopt's CHOLMOD options are one dict per process


def _analyse(matrix: Any, order: np.ndarray | None) -> Any:
    """CHOLMOD's symbolic factorization of cvxopt's upper triangle `matrix`: on `order` (a
    permutation of its rows) alone when given, else on CHOLMOD's own AMD ordering. With an
    order, CHOLMOD's default strategy would also compute AMD's to compare (0.1 s of its
    0.2 s at 228k unknowns, and METIS's was the one kept): one method only (nmethods 1)."""
    import cvxopt
    from cvxopt import cholmod

    with _CHOLMOD_OPTIONS:
        if order is None:
            return cholmod.symbolic(matrix, uplo="U")
        saved = dict(cholmod.options)
        cholmod.options["nmethods"] = 1
        try:
            return cholmod.symbolic(matrix, p=cvxopt.matrix(order.astype(np.int64)), uplo="U")
        finally:
            cholmod.options.clear()
            cholmod.options.update(saved)


def _cvxopt_upper(upper: sp.csc_matrix) -> tuple[Any, np.ndarray | None]:
    """cvxopt's spmatrix of the upper triangle `upper` (CSC), and the order its entries were
    taken in: cvxopt's, column then row (None: the CSC's own, when its rows are sorted)."""
    import cvxopt

    n = upper.shape[0]
    cols = np.repeat(np.arange(n), np.diff(upper.indptr))
    order = None if upper.has_sorted_indices else np.lexsort((upper.indices, cols))

    def taken(a: np.ndarray) -> np.ndarray:
        return a if order is None else a[order]

    return cvxopt.spmatrix(cvxopt.matrix(taken(upper.data).astype(np.float64)),
                           cvxopt.matrix(taken(upper.indices).astype(np.int64)),
                           cvxopt.matrix(taken(cols).astype(np.int64)), (n, n)), order


class Cholmod:
    """The "cholmod" backend's object of one net: CHOLMOD's supernodal Cholesky L L^T of S
    (cvxopt's build), its ordering (AMD; from METIS_MIN_DOFS unknowns METIS's nested
    dissection of the node graph when `pymetis` is installed, `nested_dissection`) and
    symbolic analysis once per pattern, then numeric factorizations only, which replace the
    values of one cvxopt matrix in place. The first S that is not positive definite (the
    follower term's symmetric part, or a tangent made indefinite by the line search's trial
    states) turns the net to the "ldl" backend's LDL^T (qdldl) for good, or raises when that
    is not installed.

    Why this one (1 thread, the simple scene's S): qdldl's LDL^T is column by column, and a
    2D net's factor fills in (0.26 s a numeric factorization at 57k unknowns, 3.9 s at 228k);
    CHOLMOD's supernodal blocks take 0.05 and 0.33 s on the same AMD ordering. Tried and
    dropped: CHOLMOD's simplicial LDL^T (cvxopt's supernodal = 0) and cholespy, no faster
    than qdldl; SuperLU on a METIS nested-dissection order (pymetis), 0.52 s at 58k; METIS
    on the dof graph (0.6 s at 228k: the node graph has a ninth of its entries); CHOLMOD's
    other settings through cvxopt (postordering off, nmethods 2 or 9, supernodal forced),
    0.34-0.35 s a numeric factorization at 228k as the defaults'; re-passes by GMRES on the
    last factorization (the "ldl" way), more Newton iterations and twice the CPU at 57k,
    and solved exactly that way 5-30 preconditioned solves each at 228k (a factorization
    costs 6); a nested-dissection order from the nodes' positions (recursive bisection, no
    dependency), 0.30 s a numeric factorization at 228k as AMD's; re-passes as a low-rank
    update of the last factorization (Woodbury), which needs one solve per changed strand:
    cvxopt solves the right-hand sides one by one (0.05 s each at 228k, 6 for a
    factorization's cost) while a re-pass there changes 2-604 strands."""

    def __init__(self) -> None:
        self.matrix: Any = None  # cvxopt's spmatrix of the upper triangle (values replaced)
        self.symbolic: Any = None  # CHOLMOD's analysis (ordering, supernodes)
        self.source: Pattern | None = None  # the pattern the analysis was made for
        self.order: np.ndarray | None = None  # the upper triangle's slots in cvxopt's order
        # (None: as they are)
        self.ldl: Ldl | None = None  # the LDL^T the net turned to, once S was indefinite
        self.solve: Callable[[np.ndarray], np.ndarray] | None = None
        # CPU seconds (process_time) and calls by phase, as `Pardiso` counts them: the
        # analysis (cvxopt's matrix and CHOLMOD's symbolic factorization), the numeric
        # factorizations, the solves; CHOLMOD's own only (not the LDL^T's it may turn to)
        self.cpu = dict.fromkeys(PHASES.values(), 0.0)
        self.calls = dict.fromkeys(PHASES.values(), 0)

    def _count(self, phase: str, since: float) -> None:
        self.cpu[phase] += time.process_time() - since
        self.calls[phase] += 1

    def factor(self, pattern: Pattern, data: np.ndarray) -> None:
        if self.ldl is not None:
            self.ldl.factor(pattern, data)
            self.solve = self.ldl.solve
            return
        import cvxopt
        from cvxopt import cholmod

        upper = pattern.symmetric_upper(data)
        t0 = time.process_time()
        if self.source is not pattern:  # a new net's pattern: analyse it
            n = upper.shape[0]
            self.matrix, self.order = _cvxopt_upper(upper)
            self.symbolic = _analyse(self.matrix, nested_dissection(pattern)
                                     if n >= METIS_MIN_DOFS else None)
            self.source = pattern
            if len(self.matrix.V) != upper.nnz:  # cvxopt merged or dropped slots
                raise ValueError("cvxopt's matrix lost entries of the pattern")
            self._count("analysis", t0)
            t0 = time.process_time()
        else:
            self.matrix.V = cvxopt.matrix(self._ordered(upper.data))
        self.solve = None
        try:
            cholmod.numeric(self.matrix, self.symbolic)
            self._count("factorization", t0)
        except ArithmeticError:  # not positive definite
            if not ldl_available():
                raise
            self.ldl = Ldl()
            self.factor(pattern, data)
            return
        self.solve = self._solve

    def _ordered(self, a: np.ndarray) -> np.ndarray:
        """Per-slot values `a` of the upper triangle in cvxopt's order."""
        return a if self.order is None else a[self.order]

    def _solve(self, b: np.ndarray) -> np.ndarray:
        import cvxopt
        from cvxopt import cholmod

        t0 = time.process_time()
        x = cvxopt.matrix(np.ascontiguousarray(b, dtype=np.float64))
        cholmod.solve(self.symbolic, x)
        self._count("solve", t0)
        return np.asarray(x).ravel()


def cholmod_solve(upper: sp.csc_matrix, rhs: np.ndarray) -> np.ndarray | None:
    """X with A X = rhs (columns) by CHOLMOD's Cholesky of the symmetric positive definite A
    given by its upper triangle (CSC, rows sorted), analysed on AMD; None when A is not
    positive definite. One factorization for all the columns."""
    import cvxopt
    from cvxopt import cholmod

    matrix, _ = _cvxopt_upper(upper)
    try:
        factor = _analyse(matrix, None)
        cholmod.numeric(matrix, factor)
    except ArithmeticError:  # not positive definite
        return None
    x = cvxopt.matrix(np.asfortranarray(rhs, dtype=np.float64))
    cholmod.solve(factor, x)
    return np.asarray(x).reshape(rhs.shape)


class Factorization:
    """One factorization of A = J + mu D; `solve` returns None when A is singular.

    backend "pardiso", "cholmod", "ldl" or "lu" (see the module docstring); `handle`: the
    backend's object from an earlier factorization of the same net (a Cholmod, an Ldl, a
    Pardiso), reused so the
    ordering is not computed again.
    """

    def __init__(self, pattern: Pattern, data: np.ndarray, backend: str, handle=None) -> None:
        self.pattern, self.A, self.backend = pattern, pattern.csr(data), backend
        self.handle: Any = None  # the backend's object (Cholmod, Ldl, Pardiso)
        self.direct: Callable[[np.ndarray], np.ndarray] | None = None  # its solve
        self.symmetric = False
        self.lu: Any = None  # scipy's SuperLU, when it is needed
        self.ok = True
        self.a_norm: float | None = None  # max row sum of |A|, once a solve needs it
        self.last: tuple[np.ndarray, np.ndarray] | None = None  # (b, S^-1 b) of the last solve
        try:
            if backend == "ldl":
                self._factor_ldl(data, handle)
            elif backend == "cholmod":
                handle = handle if handle is not None else Cholmod()
                handle.factor(pattern, data)
                self.handle, self.direct, self.symmetric = handle, handle.solve, True
            elif backend == "pardiso":
                handle = handle if handle is not None else Pardiso()
                handle.factor(pattern.symmetric_upper_csr(data))
                self.handle, self.direct, self.symmetric = handle, handle.solve, True
        except Exception:  # noqa: BLE001 - a zero pivot or a solver error: SuperLU decides
            self.handle, self.direct = None, None
        if self.direct is None:
            self._factor_lu()

    def _factor_ldl(self, data: np.ndarray, handle: Ldl | None) -> None:
        handle = handle if handle is not None else Ldl()
        handle.factor(self.pattern, data)
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

    def _a_norm(self) -> float:
        """max row sum of |A|, computed once a backward-error test needs it."""
        if self.a_norm is None:
            self.a_norm = row_sum_norm(self.A, self.pattern.row_starts)
        return self.a_norm

    def _refined(self, b: np.ndarray, forcing: float) -> np.ndarray | None:
        """The direct solve, then GMRES on A preconditioned by it when that misses the
        target (the follower term, with an LDL^T of S); None unless the target is met."""
        direct = self.direct
        if direct is None:
            return None
        try:
            with np.errstate(all="ignore"):
                x = direct(b)
                self.last = (b, x.copy())
                return refine(self.A, direct, b, x, forcing, self._a_norm)
        except Exception:  # noqa: BLE001 - a failing backend: SuperLU decides
            return None


Norm = float | Callable[[], float]  # A's row-sum norm, or how to get it when a test needs it


def lazy_norm(A: sp.csr_matrix, starts: np.ndarray | None = None) -> Callable[[], float]:
    """`row_sum_norm(A, starts)`, computed at the first call only (a solve that meets its
    forcing target never needs it)."""
    known: list[float] = []

    def norm() -> float:
        if not known:
            known.append(row_sum_norm(A, starts))
        return known[0]

    return norm


def row_sum_norm(A: sp.csr_matrix, starts: np.ndarray | None = None) -> float:
    """max row sum of |A| (the infinity norm of the backward-error test), summed over A's
    stored entries row by row (a tenth of the time of abs(A).sum(axis=1)); `starts`: the
    CSR starts of the rows that have entries, when known (`Pattern.row_starts`)."""
    if not A.nnz:
        return 0.0
    if starts is None:
        starts = A.indptr[:-1][np.diff(A.indptr) > 0]  # the rows that have entries
    return float(np.add.reduceat(np.abs(A.data), starts).max())


def meets(A: sp.csr_matrix, b: np.ndarray, x: np.ndarray, forcing: float, a_norm: Norm
          ) -> bool:
    """x solves A x = b to a backward error of LINEAR_RTOL, or (inexact Newton) to a
    residual max |b - A x| <= forcing max |b|. a_norm: A's row-sum norm, or a function
    giving it (called only when the forcing test fails)."""
    return _meets(A, b, x, forcing, a_norm)[0]


def _meets(A: sp.csr_matrix, b: np.ndarray, x: np.ndarray, forcing: float, a_norm: Norm
           ) -> tuple[bool, np.ndarray | None]:
    """(`meets`, the residual b - A x it computed, or None): the residual is GMRES's first."""
    if not np.all(np.isfinite(x)):
        return False, None
    b_norm = float(np.abs(b).max()) if b.size else 0.0
    r = b - A @ x if b.size else None
    res = float(np.abs(r).max()) if r is not None else 0.0
    if res <= forcing * b_norm:
        return True, r
    norm = a_norm() if callable(a_norm) else a_norm
    return res <= LINEAR_RTOL * (norm * float(np.abs(x).max()) + b_norm), r


def refine(A: sp.csr_matrix, precondition: Callable[[np.ndarray], np.ndarray], b: np.ndarray,
           x: np.ndarray, forcing: float, a_norm: Norm) -> np.ndarray | None:
    """x when it `meets` the target, else GMRES on A preconditioned by `precondition` from
    x; None unless the result meets it."""
    ok, r = _meets(A, b, x, forcing, a_norm)
    if ok:
        return x
    if not np.all(np.isfinite(x)):
        return None
    b_norm = float(np.abs(b).max()) if b.size else 0.0
    target = max(forcing * b_norm, GMRES_RTOL * float(np.linalg.norm(b)))
    x = gmres(A, precondition, b, x, target, GMRES_RESTART, r)
    return x if meets(A, b, x, forcing, a_norm) else None


def gmres(A: sp.csr_matrix, precondition: Callable[[np.ndarray], np.ndarray], b: np.ndarray,
          x0: np.ndarray, target: float, m: int, r0: np.ndarray | None = None) -> np.ndarray:
    """One cycle of right-preconditioned GMRES(m): x0 + M^-1 V y minimising |b - A x|_2 over
    the Krylov space of A M^-1, stopped when |b - A x|_2 <= target (classical Gram-Schmidt,
    twice; the Hessenberg matrix reduced by Givens rotations as it grows, so the residual
    norm is known at every step without a least-squares solve); r0: b - A x0 when the
    caller has it."""
    r0 = b - A @ x0 if r0 is None else r0
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
