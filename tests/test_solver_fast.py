"""The fast path (fixed pattern, LDL^T + GMRES, membrane start, chord steps, path predictor)
against the reference path (COO assembly, SuperLU every step): the same equilibrium."""

from __future__ import annotations

import dataclasses
import sys
from collections.abc import Callable

import numpy as np
import pytest
import scipy.sparse as sp

from printgen.solver import Hydrostatic, Net, SlidingCable, linear, solve, solve_path
from printgen.solver.driver import PATH_CHOLMOD_MIN_DOFS, FastSolver, _shifted, path_backend
from printgen.solver.linsolve import (
    CHOLMOD_MIN_DOFS,
    PARDISO_MIN_DOFS,
    Factorization,
    cholmod_available,
    choose_backend,
    ldl_available,
    pardiso_available,
)
from printgen.solver.scenes import simple_scene, square_net
from printgen.solver.state import NetSystem, evaluate, tangent_values

AGREE = 1e-9  # fast and reference displacements agree to 1e-9 of the largest one
TIGHT = 1e-12  # solver tolerance of both paths here: far below AGREE
LINEAR = 1e-10  # relative residual |b - A x| / |b| of a checked linear solve


def _agree(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a - b).max() / np.abs(b).max())


def _sliding_net(strand: float = 1e5) -> tuple[Net, list]:
    """A 2 x 1 m square net (0.1 m mesh; strands of axial stiffness `strand`, N) on anchors
    at the bed and the sides, its top edge threaded on a sliding cable between the two top
    corners, loaded hydrostatically with the water at 90 % of the height (z at the current
    node height)."""
    nodes, el, idx = square_net(2.0, 1.0, 0.1)
    x, z = nodes[:, 0], nodes[:, 2]
    fixed = (x < 1e-9) | (x > 2 - 1e-9) | (z < 1e-9)
    top = idx[:, -1]
    cable = SlidingCable(top, linear(4e5))
    net = Net(nodes, fixed, el, [linear(strand)], cables=[cable])
    free = np.flatnonzero(~fixed)
    return net, [Hydrostatic(free, 0.01, 0.9)]


@pytest.mark.slow
@pytest.mark.parametrize("current_z", [False, True])
def test_fast_and_reference_agree_on_simple_pinned(current_z):
    sc = simple_scene(current_z=current_z)
    fast = solve(sc.net, sc.loads_at(1.0), tol=TIGHT)
    ref = solve(sc.net, sc.loads_at(1.0), tol=TIGHT, method="reference")
    assert fast.converged and ref.converged
    assert _agree(fast.displacements, ref.displacements) < AGREE
    assert _agree(fast.tensions, ref.tensions) < AGREE
    assert fast.factorizations >= 1


def test_fast_and_reference_agree_on_a_sliding_cable_net():
    net, loads = _sliding_net()
    fast = solve(net, loads, tol=TIGHT)
    ref = solve(net, loads, tol=TIGHT, method="reference")
    assert fast.converged and ref.converged
    assert fast.cable_tensions[0] > 0  # the cable carries load: the case is exercised
    assert _agree(fast.displacements, ref.displacements) < AGREE
    assert fast.cable_tensions[0] == pytest.approx(ref.cable_tensions[0], rel=AGREE)


@pytest.mark.slow
def test_paths_agree_level_by_level():
    """Hydrostatic at the current node height, no drag (its sharp switch at a node's height
    makes the tightest tolerances a matter of luck for either path)."""
    sc = simple_scene(current_z=True, drag=False)
    levels = [0.25, 0.5, 0.75, 1.0]
    fast = solve_path(sc.net, sc.loads_at, levels, tol=TIGHT)
    ref = solve_path(sc.net, sc.loads_at, levels, tol=TIGHT, method="reference")
    assert all(r.converged for r in fast + ref)
    for f, r in zip(fast, ref, strict=True):
        assert _agree(f.displacements, r.displacements) < AGREE


@pytest.mark.slow
@pytest.mark.parametrize("refine", [0.5, 1])
def test_a_drag_load_path_converges_where_the_level_sits_on_a_node_row(refine):
    """simple-pinned with drag from h/h_B = 0 to 1.1 by 0.05: at 0.9 the water level sits on a
    node row (both meshes), where a sharp drag switch made a node's load jump as it moved and
    no level-0.9 equilibrium existed (400 iterations, 6 step cuts); the scene's drag ramps in
    over one node row, as printgen's drag load case does."""
    sc = simple_scene(refine=refine)
    levels = np.round(np.arange(0.0, 1.1001, 0.05), 10)
    results = solve_path(sc.net, sc.loads_at, levels, tol=1e-6)
    assert [r.level for r in results if not r.converged] == []


def test_without_the_optional_ldl_the_superlu_fallback_gives_the_same_answer(monkeypatch):
    """`qdldl`, `cvxopt` and `pypardiso` not importable (the `fast` extra absent): every
    solve goes through SuperLU."""
    net, loads = _sliding_net()
    with_ldl = solve(net, loads, tol=TIGHT)
    for name in ("qdldl", "cvxopt", "cvxopt.cholmod", "pypardiso"):
        monkeypatch.setitem(sys.modules, name, None)  # import now raises ImportError
    assert not ldl_available() and not pardiso_available() and not cholmod_available()
    assert choose_backend(10**6) == "lu"
    fs = FastSolver(net)
    assert fs.stepper.backend == "lu"
    plain = fs.solve(loads, [], TIGHT, 400)
    assert plain.converged
    assert _agree(plain.displacements, with_ldl.displacements) < AGREE


def _skip_unless_installed(backend: str) -> None:
    installed = {"ldl": ldl_available, "cholmod": cholmod_available,
                 "pardiso": pardiso_available}.get(backend, lambda: True)
    if not installed():
        pytest.skip(f"{backend} not installed")


@pytest.mark.parametrize("backend", ["ldl", "cholmod", "pardiso", "lu"])
def test_linear_solves_include_the_follower_term(backend):
    """With the hydrostatic load at the current node height the tangent is not symmetric:
    the LDL^T of its symmetric part + GMRES (and every other backend) must still solve the
    true system."""
    _skip_unless_installed(backend)
    sc = simple_scene(current_z=True)
    ns = NetSystem(sc.net)
    ns.loads = sc.loads_at(1.0)
    u = solve(sc.net, sc.loads_at(1.0), tol=1e-4).displacements / ns.L
    data = tangent_values(ns, evaluate(ns, u))
    A = ns.pattern.csr(data)
    assert abs(A - A.T).max() > 0  # the follower term is there
    b = np.random.default_rng(1).normal(size=ns.pattern.size)
    x = Factorization(ns.pattern, data, backend).solve(b)
    assert np.linalg.norm(A @ x - b) <= LINEAR * np.linalg.norm(b)


def test_unknown_method_is_rejected():
    sc = simple_scene()
    with pytest.raises(ValueError, match="method"):
        solve(sc.net, sc.loads_at(1.0), method="fastest")


needs_pardiso = pytest.mark.skipif(not pardiso_available(), reason="pypardiso not installed")


def _tangent(net: Net, loads: list) -> tuple[NetSystem, np.ndarray]:
    """The fast path's tangent data of a net near its equilibrium (follower term included
    when the water loads at the current node height)."""
    ns = NetSystem(net)
    ns.loads = loads
    u = solve(net, loads, tol=1e-4).displacements / ns.L
    return ns, tangent_values(ns, evaluate(ns, u))


@needs_pardiso
@pytest.mark.parametrize("case", ["pinned, follower load", "sliding cable"])
def test_pardiso_backend_and_reference_agree(case):
    """PARDISO (a Cholesky of the symmetric part, GMRES for the follower term) forced on
    small nets, below PARDISO_MIN_DOFS: the reference path's equilibrium."""
    if case == "sliding cable":
        net, loads = _sliding_net()
    else:
        sc = simple_scene(current_z=True)
        net, loads = sc.net, sc.loads_at(1.0)
    fast = FastSolver(net, backend="pardiso").solve(loads, [], TIGHT, 400)
    ref = solve(net, loads, tol=TIGHT, method="reference")
    assert fast.converged and ref.converged and fast.backend == "pardiso"
    assert _agree(fast.displacements, ref.displacements) < AGREE
    assert _agree(fast.tensions, ref.tensions) < AGREE


@needs_pardiso
def test_pardiso_turns_to_ldlt_when_the_matrix_is_indefinite():
    """A shift of the diagonal by half its largest entry makes S indefinite: the Cholesky
    meets a negative pivot, PARDISO switches to Bunch-Kaufman LDL^T, the solve stays exact."""
    ns, data = _tangent(*_sliding_net())
    data = data.copy()
    data[ns.pattern.diagonal] -= 0.5 * data[ns.pattern.diagonal].max()
    A = ns.pattern.csr(data)
    assert np.linalg.eigvalsh(0.5 * (A + A.T).toarray()).min() < 0  # indefinite indeed
    fact = Factorization(ns.pattern, data, "pardiso")
    assert fact.handle is not None and fact.handle.solver.mtype == -2
    b = np.random.default_rng(2).normal(size=ns.pattern.size)
    x = fact.solve(b)
    assert np.linalg.norm(A @ x - b) <= LINEAR * np.linalg.norm(b)


@needs_pardiso
def test_a_failing_pardiso_falls_back_to_superlu(monkeypatch):
    """PARDISO raising at the factorization or at a solve: SuperLU on A decides, and the
    whole solve still ends on the reference equilibrium."""
    from printgen.solver import linsolve

    sc = simple_scene(current_z=True)
    ns, data = _tangent(sc.net, sc.loads_at(1.0))
    A = ns.pattern.csr(data)
    b = np.random.default_rng(3).normal(size=ns.pattern.size)

    def broken(self, *args):
        raise RuntimeError("PARDISO failed")

    monkeypatch.setattr(linsolve.Pardiso, "solve", broken)
    fact = Factorization(ns.pattern, data, "pardiso")
    assert fact.direct is not None  # factorized, then every solve fails
    x = fact.solve(b)
    assert fact.lu is not None and np.linalg.norm(A @ x - b) <= LINEAR * np.linalg.norm(b)
    monkeypatch.setattr(linsolve.Pardiso, "factor", broken)
    fact = Factorization(ns.pattern, data, "pardiso")
    assert fact.direct is None and fact.lu is not None
    fast = FastSolver(sc.net, backend="pardiso").solve(sc.loads_at(1.0), [], TIGHT, 400)
    ref = solve(sc.net, sc.loads_at(1.0), tol=TIGHT, method="reference")
    assert fast.converged and _agree(fast.displacements, ref.displacements) < AGREE


@needs_pardiso
@pytest.mark.skipif(not ldl_available(), reason="qdldl not installed")
def test_ldl_turns_to_pardiso_on_a_net_factorized_often():
    """The "ldl" backend's object of a net: qdldl for its first LDL_TO_PARDISO
    factorizations, PARDISO (on LDL_PARDISO_THREADS threads) for the later ones; both solve
    the same system (the follower term by GMRES), and a single solve of the 61 x 21 net
    stays on qdldl (no MKL for it)."""
    from printgen.solver import linsolve

    sc = simple_scene(current_z=True)
    ns, data = _tangent(sc.net, sc.loads_at(1.0))
    assert ns.pattern.size >= linsolve.LDL_PARDISO_MIN_DOFS
    A = ns.pattern.csr(data)
    b = np.random.default_rng(5).normal(size=ns.pattern.size)
    handle, kinds = None, []
    for _ in range(linsolve.LDL_TO_PARDISO + 2):
        fact = Factorization(ns.pattern, data, "ldl", handle)
        handle = fact.handle
        kinds.append("pardiso" if handle.pardiso is not None else "qdldl")
        x = fact.solve(b)
        assert np.linalg.norm(A @ x - b) <= LINEAR * np.linalg.norm(b)
    assert kinds == ["qdldl"] * linsolve.LDL_TO_PARDISO + ["pardiso"] * 2
    assert handle.pardiso.threads == linsolve.LDL_PARDISO_THREADS
    single = FastSolver(sc.net)
    single.solve(sc.loads_at(1.0), [], 1e-6, 400)
    assert 0 < single.stepper.factorizations <= linsolve.LDL_TO_PARDISO
    assert single.stepper.handle.pardiso is None


def test_backend_by_size():
    expect_small = "ldl" if ldl_available() else "lu"
    expect_large = "cholmod" if cholmod_available() else expect_small
    assert choose_backend(min(PARDISO_MIN_DOFS, CHOLMOD_MIN_DOFS) - 1) == expect_small
    if not pardiso_available():
        assert choose_backend(CHOLMOD_MIN_DOFS) == expect_large
    assert choose_backend(max(PARDISO_MIN_DOFS, CHOLMOD_MIN_DOFS)) == (
        "pardiso" if pardiso_available() else expect_large)


@pytest.mark.parametrize("backend", ["ldl", "cholmod", "pardiso"])
def test_symmetric_solve_is_that_of_the_symmetric_part(backend):
    """symmetric_solve(b) solves S x = b, whether b is the last solve's right-hand side (its
    result is reused) or a new one."""
    _skip_unless_installed(backend)
    ns, data = _tangent(*_sliding_net())
    A = ns.pattern.csr(data)
    S = 0.5 * (A + A.T)
    rng = np.random.default_rng(4)
    fact = Factorization(ns.pattern, data, backend)
    for b in (rng.normal(size=ns.pattern.size), rng.normal(size=ns.pattern.size)):
        x = fact.solve(b)
        assert np.linalg.norm(A @ x - b) <= LINEAR * np.linalg.norm(b)
        for rhs in (b, rng.normal(size=ns.pattern.size)):
            y = fact.symmetric_solve(rhs)
            assert np.linalg.norm(S @ y - rhs) <= LINEAR * np.linalg.norm(rhs)


GMRES_TOL = 1e-12  # relative 2-norm residual asked of GMRES (far above round-off, n = 200)


def test_gmres_reaches_its_target_on_a_nonsymmetric_system():
    """Right-preconditioned GMRES (Givens-reduced Hessenberg) against the stated residual
    target: tight target met, a loose target stops early but still meets it."""
    from printgen.solver.linsolve import gmres

    rng = np.random.default_rng(0)
    n = 200
    A = sp.csr_matrix(np.eye(n) * 4 + rng.normal(size=(n, n)) * 0.1)
    b = rng.normal(size=n)
    for rel in (GMRES_TOL, 1e-3):
        x = gmres(A, lambda v: v / 4, b, np.zeros(n), rel * np.linalg.norm(b), 60)
        assert np.linalg.norm(b - A @ x) <= rel * np.linalg.norm(b) * (1 + 1e-6)
    x = gmres(A, lambda v: v / 4, b, np.zeros(n), GMRES_TOL * np.linalg.norm(b), 60)
    assert np.allclose(x, np.linalg.solve(A.toarray(), b), rtol=1e-9, atol=1e-12)


ROUND = 1e-12  # relative round-off of one strand's tension


def test_predicted_tensions_follow_the_linearised_law_and_stay_tension_only():
    """Mixed-integration-point Newton (solver.fast._predicted_tensions): along the strand the
    linearised law is exact for a linear law; a transverse step predicts no change (the exact
    tension grows by the second-order stretch it leaves out); a step past the rest length
    predicts zero, never compression; half a step moves the prediction half-way."""
    from printgen.solver.fast import _predicted_tensions

    net = Net(np.array([[0.0, 0, 0], [1.0, 0, 0]]), np.array([True, False]),
              np.array([[0, 1]]), [linear(100.0)])
    ns = NetSystem(net)
    u = np.zeros((2, 3))
    u[1, 0] = 0.01 / ns.L
    st = evaluate(ns, u)
    t0 = st.bar[1][0]
    along = np.array([0.005, 0.0, 0.0]) / ns.L
    exact = evaluate(ns, u + np.vstack([np.zeros(3), along])).bar[1][0]
    assert abs(_predicted_tensions(ns, st, None, along, 1.0, None)[0] - exact) <= ROUND * exact
    half = _predicted_tensions(ns, st, None, along, 0.5, None)[0]
    assert abs(half - (t0 + exact) / 2) <= ROUND * exact
    across = np.array([0.0, 0.1, 0.0]) / ns.L
    assert abs(_predicted_tensions(ns, st, None, across, 1.0, None)[0] - t0) <= ROUND * t0
    # +0.1^2 / 2 of strain
    assert evaluate(ns, u + np.vstack([np.zeros(3), across])).bar[1][0] > 1.4 * t0
    back = np.array([-0.05, 0.0, 0.0]) / ns.L
    assert _predicted_tensions(ns, st, None, back, 1.0, None)[0] == 0.0


def test_a_failing_level_is_cut_from_the_last_converged_sub_step(monkeypatch):
    """Sub-steps halve from the last converged state: with a solver that converges only on
    increments of at most 0.3, the path 0 -> 1 goes 1 (fails), 0.5 (fails), 0.25, 0.5,
    0.75, 1.0, never solving a reached load twice; with one halving allowed it stops."""
    tried: list[float] = []
    reached = [0.0]
    original = FastSolver.solve

    def only_small_steps(self, loads, starts, tol, max_iter, level=None):
        res = original(self, loads, starts, tol, max_iter, level)
        tried.append(float(level))
        if level - reached[-1] > 0.3:  # the stand-in for a level Newton cannot reach
            return dataclasses.replace(res, converged=False, reason="too far")
        reached.append(float(level))
        return res

    monkeypatch.setattr(FastSolver, "solve", only_small_steps)
    sc = simple_scene()
    out = solve_path(sc.net, sc.loads_at, [1.0], tol=1e-6, max_cuts=2)
    assert out[0].converged
    assert tried == [1.0, 0.5, 0.25, 0.5, 0.75, 1.0]
    tried.clear()
    reached[:] = [0.0]
    out = solve_path(sc.net, sc.loads_at, [1.0], tol=1e-6, max_cuts=1, skip_failed=True)
    assert not out[0].converged and "after 1 step cuts" in out[0].reason
    assert tried == [1.0, 0.5]


@pytest.mark.parametrize("backend", ["ldl", "cholmod"])
def test_a_finished_nets_handle_serves_the_next_net_of_its_pattern(monkeypatch, backend):
    """A solve leaves its qdldl or CHOLMOD handle to the next net of the same topology (here
    another geometry: 1:10), whose factorizations are then numeric only; that net's answer
    is the one a fresh handle gives, digit for digit (same pattern: same ordering, same
    factors). A handle turned to another backend is not left."""
    import gc
    import weakref
    from collections import OrderedDict

    from printgen.solver import fast, pattern

    if not (ldl_available() if backend == "ldl" else cholmod_available()):
        pytest.skip(f"{backend} not installed")
    monkeypatch.setattr(pattern, "_shared", OrderedDict())
    first, other = simple_scene(current_z=False), simple_scene(scale=10.0, current_z=False)
    fresh = FastSolver(other.net, backend).solve(other.loads_at(1.0), [], 1e-6, 400)
    pattern.clear_shared()
    solver = FastSolver(first.net, backend)
    assert solver.stepper.handle is None
    solver.solve(first.loads_at(1.0), [], 1e-6, 400)
    left = solver.stepper.handle
    assert fast._reusable(left, solver.ns.pattern)
    del solver
    reused = FastSolver(other.net, backend)
    assert reused.ns.pattern is NetSystem(first.net).pattern
    assert reused.stepper.handle is left
    assert FastSolver(other.net, backend).stepper.handle is None  # taken: one net at a time
    res = reused.solve(other.loads_at(1.0), [], 1e-6, 400)
    assert res.converged and res.iterations == fresh.iterations
    np.testing.assert_array_equal(res.displacements, fresh.displacements)
    if backend == "cholmod":
        left.ldl = object()  # as after an indefinite S: LDL^T for good, not for the next net
    else:
        left.pardiso = object()
    assert not fast._reusable(left, reused.ns.pattern)
    last = FastSolver(first.net, backend)
    last.solve(first.loads_at(1.0), [], 1e-6, 400)
    gone = weakref.ref(last.stepper.handle)
    pattern.clear_shared()  # a pattern no longer shared keeps no handle
    del last
    gc.collect()  # a Cholmod handle refers to itself (its bound `solve`)
    assert gone() is None


def test_a_guess_is_taken_at_rest_at_the_supports():
    """A guess displaced at this net's supports (the state of a net held elsewhere) starts the
    path only where this net is free: the supports stay at rest and the path ends where it
    ends without the guess (Newton moves free degrees of freedom only, so a support's guessed
    displacement would otherwise stay in the answer)."""
    net, loads = _sliding_net()
    levels = [0.5, 1.0]
    plain = solve_path(net, lambda r: loads, levels, tol=TIGHT)
    fixed = net.fixed_dofs
    off = {lv: np.where(fixed, 0.01, r.displacements) for lv, r in zip(levels, plain,
                                                                     strict=True)}
    guessed = solve_path(net, lambda r: loads, levels, tol=TIGHT, guesses=lambda r: [off[r]])
    for a, b in zip(plain, guessed, strict=True):
        assert a.converged and b.converged
        assert not np.any(b.displacements[fixed])
        assert _agree(a.displacements, b.displacements) < AGREE


def test_a_neighbours_path_shifted_onto_this_one_starts_each_level_closer():
    """`paths`: a net 20 % stiffer, swept first, gives each level of this net's path its load
    step from the level before, added to this path's state there. The path ends where the
    cold one ends (a start, never the answer) in fewer Newton iterations in all; an entry of
    another shape (a net of another graph) and a missing level (None) are passed over."""
    levels = [0.25, 0.5, 0.75, 1.0]  # the water at these shares of its 0.9 m

    def rising(loads: list) -> Callable[[float], list]:
        return lambda r: [dataclasses.replace(h, level=h.level * r) for h in loads]

    stiff, loads_s = _sliding_net(1.2e5)
    kept = {lv: r.displacements for lv, r in zip(
        levels, solve_path(stiff, rising(loads_s), levels, tol=TIGHT), strict=True)}
    net, loads = _sliding_net()
    cold = solve_path(net, rising(loads), levels, tol=TIGHT)
    other = np.zeros((3, 3))  # another graph's state: not a start here
    warm = solve_path(net, rising(loads), levels, tol=TIGHT,
                      paths=lambda r: [kept.get(r), other, None])
    for a, b in zip(cold, warm, strict=True):
        assert a.converged and b.converged
        assert _agree(a.displacements, b.displacements) < AGREE
    assert sum(r.iterations for r in warm) < sum(r.iterations for r in cold)


def test_shifted_starts_add_the_neighbours_step_to_this_paths_state():
    """The start is this path's last state plus the neighbour's change from that level to the
    target, at rest at the supports; the neighbour's own state before this path has converged
    anywhere or where it has no state at the last level; nothing from a net without the
    target level."""
    fixed = np.array([[True, True, True], [False, False, False]])
    u = np.array([[0.0, 0.0, 0.0], [1.0, 2.0, 3.0]])
    g = {0.5: np.full((2, 3), 0.5), 1.0: np.full((2, 3), 0.75)}
    [start] = _shifted(lambda r: [g.get(r)], [(0.5, u)], 1.0, fixed)
    np.testing.assert_array_equal(start, u + np.where(fixed, 0.0, 0.25))
    [first] = _shifted(lambda r: [g.get(r)], [], 1.0, fixed)
    np.testing.assert_array_equal(first, np.where(fixed, 0.0, 0.75))
    [own] = _shifted(lambda r: [g.get(r)], [(0.25, u)], 1.0, fixed)  # none at 0.25
    np.testing.assert_array_equal(own, np.where(fixed, 0.0, 0.75))
    assert _shifted(lambda r: [g.get(r)], [(0.5, u)], 0.8, fixed) == []


def test_a_load_path_takes_cholmod_from_its_threshold_when_qdldl_would_factorize():
    """`path_backend`: CHOLMOD from PATH_CHOLMOD_MIN_DOFS unknowns in place of qdldl (when
    installed), `choose_backend`'s otherwise (PARDISO's preference kept)."""
    below = PATH_CHOLMOD_MIN_DOFS - 1
    assert path_backend(below) == choose_backend(below)
    at = PATH_CHOLMOD_MIN_DOFS
    single = choose_backend(at)
    assert path_backend(at) == ("cholmod" if single == "ldl" and cholmod_available()
                                else single)
    big = max(PARDISO_MIN_DOFS, CHOLMOD_MIN_DOFS)
    assert path_backend(big) == choose_backend(big)
