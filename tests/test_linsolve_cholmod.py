"""The "cholmod" backend of `solver.linsolve`: CHOLMOD's supernodal Cholesky of the symmetric
part through cvxopt (the `fast` extra), analysed once per net, turning to qdldl's LDL^T when
S is not positive definite; and the fast path on it against the reference path. The tests
skip when `cvxopt` is absent."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from printgen.solver import Hydrostatic, Net, SlidingCable, linear, solve
from printgen.solver.driver import FastSolver
from printgen.solver.linsolve import Cholmod, Factorization, cholmod_available, ldl_available
from printgen.solver.scenes import simple_scene, square_net
from printgen.solver.state import NetSystem, evaluate, tangent_values

pytestmark = pytest.mark.skipif(not cholmod_available(), reason="cvxopt not installed")

AGREE = 1e-9  # fast and reference displacements agree to 1e-9 of the largest one (the
# fast path's acceptance bound, as in test_solver_fast)
TIGHT = 1e-12  # solver tolerance of both paths here: far below AGREE
LINEAR = 1e-10  # relative residual |b - A x| / |b| of a checked linear solve (well-conditioned
# tangents of these small nets: a direct solve reaches ~1e-14)


def _agree(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a - b).max() / np.abs(b).max())


def _sliding_net() -> tuple[Net, list]:
    """A 2 x 1 m square net (0.1 m mesh) on anchors at the bed and the sides, its top edge on a
    sliding cable, loaded hydrostatically at the current node height (water at 90 %)."""
    nodes, el, idx = square_net(2.0, 1.0, 0.1)
    x, z = nodes[:, 0], nodes[:, 2]
    fixed = (x < 1e-9) | (x > 2 - 1e-9) | (z < 1e-9)
    net = Net(nodes, fixed, el, [linear(1e5)], cables=[SlidingCable(idx[:, -1], linear(4e5))])
    return net, [Hydrostatic(np.flatnonzero(~fixed), 0.01, 0.9)]


def _tangent(net: Net, loads: list) -> tuple[NetSystem, np.ndarray]:
    """The fast path's tangent data near the equilibrium (follower term included)."""
    ns = NetSystem(net)
    ns.loads = loads
    u = solve(net, loads, tol=1e-4).displacements / ns.L
    return ns, tangent_values(ns, evaluate(ns, u))


def _residual(A, x: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(A @ x - b) / np.linalg.norm(b))


def test_cholmod_refactorizes_on_the_same_pattern_without_a_new_analysis():
    """New values on the same net: the same analysis (CHOLMOD's symbolic object) and matrix,
    every solve that of the latest values, the follower term repaired by GMRES."""
    sc = simple_scene(current_z=True)
    ns, data = _tangent(sc.net, sc.loads_at(1.0))
    b = np.random.default_rng(1).normal(size=ns.pattern.size)
    first = Factorization(ns.pattern, data, "cholmod")
    handle = first.handle
    assert isinstance(handle, Cholmod) and handle.ldl is None
    symbolic, matrix = handle.symbolic, handle.matrix
    for scale in (1.0, 3.0):
        fact = Factorization(ns.pattern, scale * data, "cholmod", handle)
        assert fact.handle is handle and handle.symbolic is symbolic and handle.matrix is matrix
        x = fact.solve(b)
        assert _residual(ns.pattern.csr(scale * data), x, b) <= LINEAR


def test_cholmod_counts_its_phases():
    """One analysis per pattern, one count per numeric factorization and per solve, and CPU
    time in each (what bench solver's size table reports beside PARDISO's)."""
    sc = simple_scene(current_z=True)
    ns, data = _tangent(sc.net, sc.loads_at(1.0))
    handle = Cholmod()
    for scale in (1.0, 2.0, 3.0):
        handle.factor(ns.pattern, scale * data)
    assert handle.solve is not None
    handle.solve(np.ones(ns.pattern.size))
    assert handle.calls == {"analysis": 1, "factorization": 3, "solve": 1}
    assert all(handle.cpu[phase] >= 0.0 for phase in handle.calls)
    assert handle.cpu["factorization"] > 0.0


@pytest.mark.skipif(not ldl_available(), reason="qdldl not installed")
def test_cholmod_turns_to_ldlt_when_the_matrix_is_indefinite():
    """A shift of the diagonal by half its largest entry makes S indefinite: the Cholesky
    fails, the net turns to qdldl's LDL^T for good (a later positive definite S too) and the
    solves stay exact."""
    ns, data = _tangent(*_sliding_net())
    shifted = data.copy()
    shifted[ns.pattern.diagonal] -= 0.5 * shifted[ns.pattern.diagonal].max()
    A = ns.pattern.csr(shifted)
    assert np.linalg.eigvalsh(0.5 * (A + A.T).toarray()).min() < 0  # indefinite indeed
    b = np.random.default_rng(2).normal(size=ns.pattern.size)
    fact = Factorization(ns.pattern, shifted, "cholmod")
    assert fact.handle is not None and fact.handle.ldl is not None and fact.lu is None
    assert _residual(A, fact.solve(b), b) <= LINEAR
    again = Factorization(ns.pattern, data, "cholmod", fact.handle)
    assert again.handle.ldl is fact.handle.ldl
    assert _residual(ns.pattern.csr(data), again.solve(b), b) <= LINEAR


@pytest.mark.parametrize("case", ["pinned, follower load", "sliding cable"])
def test_cholmod_backend_and_reference_agree(case):
    """CHOLMOD forced on small nets, below CHOLMOD_MIN_DOFS: the reference path's
    equilibrium."""
    if case == "sliding cable":
        net, loads = _sliding_net()
    else:
        sc = simple_scene(current_z=True)
        net, loads = sc.net, sc.loads_at(1.0)
    fast = FastSolver(net, backend="cholmod").solve(loads, [], TIGHT, 400)
    ref = solve(net, loads, tol=TIGHT, method="reference")
    assert fast.converged and ref.converged and fast.backend == "cholmod"
    assert _agree(fast.displacements, ref.displacements) < AGREE
    assert _agree(fast.tensions, ref.tensions) < AGREE


@pytest.mark.parametrize("kw", [{"slack": 0.02}, {"modulus": 5e8}])
def test_cholmod_and_ldl_agree_on_hard_cases(kw):
    """Hard cases of the robustness table (2 % slack; very soft strands, ~40 % strain) at its
    two load levels, each from rest: CHOLMOD and qdldl reach the same equilibria. (Not at
    half load: there the 2 % slack net's slack panels have many equilibria, and qdldl,
    SuperLU and the reference path already end on different ones, a few per cent apart.)"""
    if not ldl_available():
        pytest.skip("qdldl not installed")
    sc = simple_scene(**kw)
    levels = [1.0, 1.1]
    runs = {}
    for backend in ("ldl", "cholmod"):
        fs = FastSolver(sc.net, backend=backend)
        runs[backend] = [fs.solve(sc.loads_at(level), [], TIGHT, 400, level)
                         for level in levels]
    for a, b in zip(runs["ldl"], runs["cholmod"], strict=True):
        assert a.converged and b.converged and b.backend == "cholmod"
        assert _agree(b.displacements, a.displacements) < AGREE


class _UnsortedPattern:
    """A stand-in for a net's Pattern whose upper triangle (CSC) stores each column's rows in
    reverse: a 2D grid Laplacian plus a shift (positive definite), times the value `data`."""

    def __init__(self, n: int) -> None:
        lap = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
        eye = sp.identity(n)
        upper = sp.triu(sp.kron(lap, eye) + sp.kron(eye, lap) + 0.5 * sp.identity(n * n))
        self.upper = upper.tocsc()
        self.upper.sort_indices()
        for c in range(self.upper.shape[1]):  # reverse each column's rows
            lo, hi = self.upper.indptr[c], self.upper.indptr[c + 1]
            self.upper.indices[lo:hi] = self.upper.indices[lo:hi][::-1].copy()
            self.upper.data[lo:hi] = self.upper.data[lo:hi][::-1].copy()
        self.upper.has_sorted_indices = False

    def symmetric_upper(self, data: float) -> sp.csc_matrix:
        return sp.csc_matrix((data * self.upper.data, self.upper.indices, self.upper.indptr),
                             shape=self.upper.shape)


def test_cholmod_takes_an_upper_triangle_in_any_row_order():
    """A pattern whose rows are not sorted within a column: its slots are put in cvxopt's
    order once, and every factorization (the first and a numeric-only one) solves S x = b."""
    pattern = _UnsortedPattern(9)
    handle = Cholmod()
    b = np.random.default_rng(6).normal(size=pattern.upper.shape[0])
    for scale in (1.0, 2.0):
        handle.factor(pattern, scale)  # type: ignore[arg-type]
        assert handle.order is not None and handle.solve is not None
        S = pattern.symmetric_upper(scale)
        full = S + sp.triu(S, 1).T
        assert _residual(full, handle.solve(b), b) <= LINEAR


def _with_rollers(net: Net) -> Net:
    """`net` with some free nodes held in one or two directions only (1 or 2 free dofs)."""
    fixed = np.array(net.fixed_dofs, dtype=bool)
    fixed[5::7, 1] = True
    fixed[3::11, [0, 2]] = True
    return Net(net.nodes, fixed, net.elements, net.laws, element_law=net.element_law,
               cables=net.cables)


@pytest.mark.parametrize("rollers", [False, True])
def test_the_node_graph_is_the_tangent_pattern_collapsed_to_nodes(rollers):
    """`Pattern.node_adjacency`: two nodes with free dofs are adjacent exactly where the
    tangent has an entry between their dofs (strands, the cable's segments and dense block),
    symmetric, no self-loops; `dof_order` of the nodes in their own order is every free dof
    in its own order, and of a shuffled node order each node's dofs together, in order
    (nodes with 1, 2 or 3 free dofs when `rollers`)."""
    net, _ = _sliding_net()
    ns = NetSystem(_with_rollers(net) if rollers else net)
    pattern = ns.pattern
    xadj, adjncy = pattern.node_adjacency()
    node = np.flatnonzero(ns.free) // 3
    nodes, of_dof = np.unique(node, return_inverse=True)
    rows = np.repeat(np.arange(pattern.size), np.diff(pattern.indptr))
    pairs = {(int(a), int(b)) for a, b in zip(of_dof[rows], of_dof[pattern.cols], strict=True)
             if a != b}
    graph = {(int(a), int(b)) for a in range(len(nodes)) for b in adjncy[xadj[a]:xadj[a + 1]]}
    assert graph == pairs and all((b, a) in graph for a, b in graph)
    assert len(xadj) == len(nodes) + 1 and len(adjncy) == len(graph)  # no pair twice
    np.testing.assert_array_equal(pattern.dof_order(np.arange(len(nodes))),
                                  np.arange(pattern.size))
    shuffled = np.random.default_rng(2).permutation(len(nodes))
    order = pattern.dof_order(shuffled)
    np.testing.assert_array_equal(of_dof[order], np.repeat(shuffled, np.bincount(of_dof)[shuffled]))
    assert np.all(np.diff(order)[np.diff(of_dof[order]) == 0] == 1)


def test_a_nested_dissection_order_factorizes_the_same_system(monkeypatch):
    """From METIS_MIN_DOFS unknowns CHOLMOD is analysed on METIS's nested-dissection order
    of the node graph (a permutation of the free dofs): the solves are those of the AMD
    analysis to round-off, and a net of that size solves to the same answer."""
    pytest.importorskip("pymetis")
    from printgen.solver import linsolve

    net, loads = _sliding_net()
    ns, data = _tangent(net, loads)
    order = linsolve.nested_dissection(ns.pattern)
    assert order is not None
    np.testing.assert_array_equal(np.sort(order), np.arange(ns.pattern.size))
    b = np.random.default_rng(3).normal(size=ns.pattern.size)
    amd = Factorization(ns.pattern, data, "cholmod").solve(b)
    monkeypatch.setattr(linsolve, "METIS_MIN_DOFS", 0)
    called = []
    monkeypatch.setattr(linsolve, "nested_dissection",
                        lambda pattern: called.append(pattern) or order)
    from cvxopt import cholmod

    options = dict(cholmod.options)
    fact = Factorization(ns.pattern, data, "cholmod")
    assert called == [ns.pattern] and isinstance(fact.handle, Cholmod)
    assert cholmod.options == options  # the one-method setting of the analysis undone
    x = fact.solve(b)
    assert _residual(fact.A, x, b) < LINEAR
    assert _agree(x, amd) < LINEAR
    reference = solve(net, loads, tol=TIGHT, method="reference")
    fast = FastSolver(net, "cholmod").solve(loads, [], TIGHT, 400)
    assert fast.converged and _agree(fast.displacements, reference.displacements) < AGREE


def test_without_pymetis_the_analysis_keeps_amd(monkeypatch):
    """`pymetis` not importable: no order (CHOLMOD's own AMD), whatever the net's size."""
    import sys

    from printgen.solver import linsolve

    monkeypatch.setitem(sys.modules, "pymetis", None)  # import now raises ImportError
    assert not linsolve.metis_available()
    net, _ = _sliding_net()
    assert linsolve.nested_dissection(NetSystem(net).pattern) is None
