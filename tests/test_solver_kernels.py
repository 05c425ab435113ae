"""The fast path's per-iteration kernels against the plain formulas they replace: the laws'
one-pass evaluation, the strand pass and the tangent scattered into the fixed pattern (upper
triangles of the strand blocks, hydrostatic z columns) against the reference COO assembly,
the backward-error norm, at random states of a net with interleaved laws, slack and taut
strands, a sliding cable and a follower load."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from printgen.solver import Hydrostatic, Net, SlidingCable, linear, piecewise
from printgen.solver import pattern as pattern_module
from printgen.solver.assemble import internal, strain_energy
from printgen.solver.linsolve import PARDISO_MIN_DOFS, row_sum_norm
from printgen.solver.pattern import Pattern
from printgen.solver.scenes import simple_scene, square_net
from printgen.solver.state import NetSystem, evaluate, ray_potential, tangent_values

KERNEL = 1e-14  # relative: the same products and sums, only reassociated (BLAS, bincount)
MEMBRANE = 1e-12  # relative residual of a direct sparse solve of the net's Laplacian
SHAPES_AGREE = 1e-10  # two direct solves of one small net's Laplacian (well conditioned:
# they differ by round-off times its condition number) agree to this, relative
LAWS = [linear(2.0), piecewise([0.01], [1.0, 0.3]), piecewise([0.002, 0.01, 0.05],
                                                               [0.5, 2.0, 1.0, 4.0])]


@pytest.mark.parametrize("law", LAWS + [piecewise([0.3, 0.5], [1e-3, 1e-9, 7.0])])
def test_one_pass_law_evaluation_equals_force_tangent_and_energy(law):
    rng = np.random.default_rng(0)
    eps = np.concatenate([rng.normal(0, 0.05, 400), [0.0, -1e-12], np.array(law.knees)])
    force, tangent, energy = law.evaluate(eps)
    f_ref, t_ref = law.force_and_tangent(eps)
    np.testing.assert_allclose(force, f_ref, rtol=KERNEL, atol=0)
    np.testing.assert_array_equal(tangent, t_ref)  # a slope picked, no arithmetic
    np.testing.assert_allclose(energy, law.energy(eps), rtol=KERNEL, atol=0)


def _net() -> tuple[Net, list]:
    """A 1 x 0.6 m square net, pinned around, strands of three laws interleaved (so each
    law's strands are not one block), the top edge threaded on a sliding cable, water to
    80 % of the height at the current node height (the follower term)."""
    nodes, el, idx = square_net(1.0, 0.6, 0.1)
    x, z = nodes[:, 0], nodes[:, 2]
    fixed = (x < 1e-9) | (x > 1 - 1e-9) | (z < 1e-9)
    law_index = np.arange(len(el)) % len(LAWS)
    cable = SlidingCable(idx[:, -1], linear(3.0))
    net = Net(nodes, fixed, el, LAWS, element_law=law_index, cables=[cable])
    return net, [Hydrostatic(np.flatnonzero(~fixed), 0.01, 0.48)]


def _states(ns: NetSystem, count: int):
    """Random displacement fields (nondimensional) leaving some strands slack, most taut."""
    rng = np.random.default_rng(1)
    for _ in range(count):
        u = rng.normal(0, 0.01, ns.x0.shape)
        u.ravel()[~ns.free] = 0.0
        yield u


def test_strand_groups_of_interleaved_laws_are_their_strands():
    ns = NetSystem(_net()[0])
    groups = ns.bars.groups
    assert [law for law, _ in groups] == ns.bars.laws and len(groups) == len(LAWS)
    for k, (_, sel) in enumerate(groups):
        np.testing.assert_array_equal(np.arange(len(ns.bars.rest))[sel],
                                      np.flatnonzero(ns.bars.law_index == k))


def test_strand_pass_and_energy_equal_the_reference_assembly():
    net, loads = _net()
    ns = NetSystem(net)
    ns.loads = loads
    for u in _states(ns, 4):
        st = evaluate(ns, u)
        g, _ = internal(ns.bars, ns.cables, u, ns.n, with_tangent=False)
        r_ref = (g - st.f).ravel()[ns.free]
        assert np.abs(st.r - r_ref).max() <= KERNEL * np.abs(r_ref).max()
        energy = strain_energy(ns.bars, ns.cables, u)
        assert st.energy == pytest.approx(energy, rel=KERNEL)
        slack = st.bar[1] <= 0
        assert slack.any() and not slack.all()  # both kinds of strands are exercised


def test_tangent_in_the_pattern_equals_the_reference_assembly():
    """K (COO, taut strands and cables) minus dF/du (the hydrostatic load's z-derivative on
    each node's own z column), on the free dofs."""
    net, loads = _net()
    ns = NetSystem(net)
    ns.loads = loads
    for u in _states(ns, 4):
        st = evaluate(ns, u)
        _, K = internal(ns.bars, ns.cables, u, ns.n)
        follower = np.zeros((ns.n, 3, ns.n, 3))
        follower[np.arange(ns.n), :, np.arange(ns.n), 2] = st.dz
        ref = K.toarray() - follower.reshape(3 * ns.n, 3 * ns.n)
        ref = ref[ns.free][:, ns.free]
        fast = ns.pattern.csr(tangent_values(ns, st)).toarray()
        assert np.abs(st.dz).max() > 0 and st.cab[0][0] > 0  # follower and cable present
        assert np.abs(fast - ref).max() <= KERNEL * np.abs(ref).max()


def test_row_sum_norm_with_empty_rows():
    rng = np.random.default_rng(2)
    A = sp.random(60, 60, density=0.05, random_state=rng, format="csr")
    A = A - 2 * sp.random(60, 60, density=0.05, random_state=rng, format="csr")
    A = sp.csr_matrix(A)
    assert np.diff(A.indptr).min() == 0  # some rows are empty
    assert row_sum_norm(A) == pytest.approx(float(abs(A).sum(axis=1).max()), rel=KERNEL)
    assert row_sum_norm(sp.csr_matrix((5, 5))) == 0.0


def _partly_fixed_net() -> Net:
    """`_net` with some nodes held in one or two directions only (rollers), so the pattern's
    node blocks lose single rows and columns."""
    net, _ = _net()
    fixed = np.tile(np.asarray(net.fixed, dtype=bool)[:, None], (1, 3))
    fixed[5::7, 1] = True
    fixed[3::11, [0, 2]] = True
    return Net(net.nodes, fixed, net.elements, net.laws, element_law=net.element_law,
               cables=net.cables)


def test_pattern_structure_equals_scipy_assembly():
    """The pattern built from the node blocks, against scipy's COO -> CSR of the same slot
    values: the CSR data, its transpose map, the symmetric part's upper triangle (CSC for
    qdldl, CSR for PARDISO) and the z columns, on a net with a cable and rollers."""
    ns = NetSystem(_partly_fixed_net())
    p = ns.pattern
    assert int((ns.net.fixed_dofs.sum(axis=1) % 3 != 0).sum()) > 0  # rollers present
    rng = np.random.default_rng(3)
    values = rng.normal(size=len(p.keep))
    rows, cols = _slot_rows_cols(ns)
    index = np.full(3 * ns.n, -1)
    index[ns.free] = np.arange(p.size)
    keep = (index[rows] >= 0) & (index[cols] >= 0)
    np.testing.assert_array_equal(keep, p.keep)
    ref = sp.coo_matrix((values[keep], (index[rows[keep]], index[cols[keep]])),
                        shape=(p.size, p.size)).tocsr()
    data = p.scatter(values)
    assert np.abs(p.csr(data).toarray() - ref.toarray()).max() <= KERNEL * np.abs(values).max()
    np.testing.assert_array_equal(p.rows[p.transpose], p.cols)
    np.testing.assert_array_equal(p.cols[p.transpose], p.rows)
    sym = 0.5 * (ref + ref.T)
    for upper in (p.symmetric_upper(data), p.symmetric_upper_csr(data)):
        assert np.abs(upper.toarray() - sp.triu(sym).toarray()).max() <= KERNEL * np.abs(
            values).max()
    dz = rng.normal(size=(ns.n, 3))
    z = p.assemble(np.zeros((len(ns.bars.rest), 6)), np.zeros(p.cable_map.shape[1]), dz)
    follower = np.zeros((ns.n, 3, ns.n, 3))
    follower[np.arange(ns.n), :, np.arange(ns.n), 2] = dz
    expect = -follower.reshape(3 * ns.n, 3 * ns.n)[ns.free][:, ns.free]
    np.testing.assert_array_equal(p.csr(z).toarray(), expect)


def _slot_rows_cols(ns: NetSystem) -> tuple[np.ndarray, np.ndarray]:
    """Dof rows and columns of every slot, in the pattern's slot order, written out plainly:
    per strand its blocks ii, jj, ij, ji; per cable its segments' blocks and its dense
    block; each node's diagonal block."""
    def blocks(a, b):
        r = 3 * a[:, None, None] + np.arange(3)[None, :, None]
        c = 3 * b[:, None, None] + np.arange(3)[None, None, :]
        return np.broadcast_to(r, (len(a), 3, 3)), np.broadcast_to(c, (len(a), 3, 3))

    def pairs(i, j):
        rc = [blocks(a, b) for a, b in ((i, i), (j, j), (i, j), (j, i))]
        return np.stack([r for r, _ in rc], 1).ravel(), np.stack([c for _, c in rc], 1).ravel()

    parts = [pairs(ns.bars.i, ns.bars.j)]
    for c in ns.cables:
        parts.append(pairs(c.nodes[:-1], c.nodes[1:]))
        dof = (3 * c.nodes[:, None] + np.arange(3)).ravel()
        parts.append((np.repeat(dof, len(dof)), np.tile(dof, len(dof))))
    every = np.arange(ns.n)
    parts.append(tuple(x.ravel() for x in blocks(every, every)))
    return tuple(np.concatenate(x) for x in zip(*parts, strict=True))


def test_ray_potential_equals_the_potential_along_the_ray():
    net, loads = _net()
    ns = NetSystem(net)
    ns.loads = loads
    u, w = _states(ns, 2)
    f = evaluate(ns, u).f
    along = ray_potential(ns, u, w, f)
    for t in (0.0, 1e-3, 0.3, 1.0, 2.5):
        at = u + t * w
        reference = strain_energy(ns.bars, ns.cables, at) - float((f * at).sum())
        assert along(t) == pytest.approx(reference, rel=KERNEL, abs=KERNEL)


@pytest.mark.parametrize("large", [False, True])
def test_membrane_shape_solves_the_damping_system(large):
    """D v = b / c on the free dofs (D: the net's Laplacian times I3, scaled in NetSystem to
    a mean diagonal of 1; c > 0 that scale), per direction with the rollers' own free-node
    sets; large: simple-pinned 121 x 41 (14k unknowns, PARDISO's Cholesky when installed)."""
    ns = NetSystem(simple_scene(refine=2).net if large else _partly_fixed_net())
    assert (ns.pattern.size >= PARDISO_MIN_DOFS) == large
    b = np.random.default_rng(4).normal(size=ns.pattern.size)
    Dv = ns.pattern.csr(ns.damping) @ ns.membrane_shape(b)
    c = float(b @ Dv) / float(Dv @ Dv)
    assert c > 0
    assert np.abs(c * Dv - b).max() <= MEMBRANE * np.abs(b).max()


def test_membrane_shape_by_cholmod_is_the_ldlt_s(monkeypatch):
    """From LAPLACIAN_CHOLMOD_MIN_NODES nodes (here from none) CHOLMOD's Cholesky solves the
    Laplacian, per direction with the rollers' own free-node sets: the shape of qdldl's
    LDL^T to round-off."""
    from printgen.solver import state
    from printgen.solver.linsolve import cholmod_available, ldl_available

    if not (cholmod_available() and ldl_available()):
        pytest.skip("cvxopt or qdldl not installed")
    monkeypatch.setattr(state, "pardiso_available", lambda: False)
    b = np.random.default_rng(5).normal(size=NetSystem(_partly_fixed_net()).pattern.size)
    plain = NetSystem(_partly_fixed_net()).membrane_shape(b)
    called = []
    real = state.cholmod_solve
    monkeypatch.setattr(state, "cholmod_solve", lambda u, r: called.append(u.shape) or real(u, r))
    monkeypatch.setattr(state, "LAPLACIAN_CHOLMOD_MIN_NODES", 0)
    shape = NetSystem(_partly_fixed_net()).membrane_shape(b)
    assert called and plain is not None and shape is not None
    assert np.abs(shape - plain).max() <= SHAPES_AGREE * np.abs(plain).max()


def test_membrane_shape_of_a_net_with_a_part_hanging_on_nothing_is_none():
    """A loose panel beside the net, joined to no anchor: its Laplacian is singular, though a
    factorization need not meet an exact zero pivot (LDL^T returned a finite shape of 3e11)."""
    net, _ = _net()
    n = len(net.nodes)
    panel, el, _ = square_net(0.37, 0.29, 0.013)  # irregular spacing: no exact cancellation
    fixed = np.concatenate([np.asarray(net.fixed_dofs), np.zeros((len(panel), 3), bool)])
    ns = NetSystem(Net(np.vstack([net.nodes, panel + [0.0, 1.0, 0.0]]), fixed,
                       np.vstack([net.elements, el + n]), LAWS,
                       element_law=np.concatenate([net.element_law, np.zeros(len(el), int)]),
                       cables=net.cables))
    assert ns.membrane_shape(np.ones(ns.pattern.size)) is None
    assert NetSystem(net).membrane_shape(np.ones(NetSystem(net).pattern.size)) is not None


PATTERN_ARRAYS = ("size", "nnz", "indptr", "cols", "rows", "entry", "transpose", "keep", "slot",
                  "diagonal", "upper", "upper_transpose", "upper_indices", "upper_indptr",
                  "strand_map", "cable_map", "z_slots", "z_take")


def _same_pattern(a: Pattern, b: Pattern) -> None:
    for name in PATTERN_ARRAYS:
        x, y = getattr(a, name), getattr(b, name)
        if sp.issparse(x):
            assert (x != y).nnz == 0, name
        else:
            np.testing.assert_array_equal(x, y, err_msg=name)


def test_shared_pattern_is_one_per_topology_and_equals_a_fresh_build(monkeypatch):
    """Nets of one topology (other node positions, laws, anchors' coordinates) share one
    Pattern, equal to the one built afresh; another anchor set, another strand or another
    cable gets its own; patterns past SHARED_BYTES are dropped, least recently used first."""
    monkeypatch.setattr(pattern_module, "_shared", type(pattern_module._shared)())
    net, _ = _net()
    ns = NetSystem(net)
    moved = Net(net.nodes * 1.3 + 0.1, net.fixed, net.elements, [linear(7.0)],
                cables=[SlidingCable(net.cables[0].nodes, linear(1.0))])
    assert NetSystem(moved).pattern is ns.pattern
    fresh = Pattern(ns.n, ns.free, ns.bars.i, ns.bars.j, [c.nodes for c in ns.cables])
    _same_pattern(ns.pattern, fresh)
    rollers = _partly_fixed_net()
    no_cable = Net(net.nodes, net.fixed, net.elements, LAWS, element_law=net.element_law)
    fewer = Net(net.nodes, net.fixed, net.elements[:-1], LAWS,
                element_law=net.element_law[:-1], cables=net.cables)
    others = [NetSystem(x).pattern for x in (rollers, no_cable, fewer)]
    assert len({id(p) for p in [ns.pattern, *others]}) == 4
    _same_pattern(others[0], Pattern(len(rollers.nodes), ~rollers.fixed_dofs.ravel(),
                                     ns.bars.i, ns.bars.j, [c.nodes for c in ns.cables]))
    assert len(pattern_module._shared) == 4
    # room for two of them: a new one and the one used last stay
    monkeypatch.setattr(pattern_module, "SHARED_BYTES", 2 * ns.pattern.nbytes() + 1)
    NetSystem(net)
    least = NetSystem(Net(net.nodes, net.fixed, net.elements[:-2], LAWS,
                          element_law=net.element_law[:-2], cables=net.cables)).pattern
    assert least.nbytes() < ns.pattern.nbytes()
    assert [entry[0] for entry in pattern_module._shared.values()] == [ns.pattern, least]
    pattern_module.clear_shared()
    assert NetSystem(net).pattern is not ns.pattern


def test_membrane_shape_of_a_net_reuses_its_topologys_laplacian_ordering(monkeypatch):
    """The next net of a topology (here moved and stretched, so other weights) solves its
    Laplacians with the qdldl objects the last one left (`pattern.shared_extras`): the
    shape a fresh factorization gives, digit for digit; on a net with rollers, one object
    per distinct set of free nodes."""
    from collections import OrderedDict

    from printgen.solver.linsolve import ldl_available

    if not ldl_available():
        pytest.skip("qdldl not installed")
    monkeypatch.setattr(pattern_module, "_shared", OrderedDict())
    net = _partly_fixed_net()
    moved = Net(net.nodes * [1.3, 1.0, 0.8] + 0.1, net.fixed, net.elements, net.laws,
                element_law=net.element_law, cables=net.cables)
    b = np.random.default_rng(6).normal(size=NetSystem(net).pattern.size)
    fresh = NetSystem(moved).membrane_shape(b)
    pattern_module.clear_shared()
    NetSystem(net).membrane_shape(b)
    ns = NetSystem(moved)
    spares = [v for k, v in pattern_module.shared_extras(ns.pattern).items()
              if k[0] == "laplacian"]
    assert len(spares) == 2 and all("qdldl" in s for s in spares)  # rollers: x, z vs y
    left = [s["qdldl"] for s in spares]
    np.testing.assert_array_equal(ns.membrane_shape(b), fresh)
    assert [s["qdldl"] for s in spares] == left  # used, and left again
