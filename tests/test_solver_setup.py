"""A net's fixed set-up costs (issue 28, item 3) against the plain constructions they replace:
the tangent pattern built from the node graph against the dof-level COO -> CSR of all slots,
the membrane shape's Cholesky on large nets against SuperLU (and its singular case), the
membrane start's ray potential against the strand pass."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from solver import Net, SlidingCable, linear
from solver.linsolve import PARDISO_MIN_DOFS
from solver.scenes import simple_scene, square_net
from solver.state import NetSystem, evaluate, potential, ray_potential

KERNEL = 1e-13  # relative: the same sums, reassociated (one quadratic in s per strand)
START = 1e-9  # relative: two direct solves of the same SPD Laplacian (round-off of the factors)


def _net(partly_fixed: bool = True) -> Net:
    """A 1 x 0.6 m square net on the bed and the banks, the top threaded on a sliding cable;
    some free nodes held in y only (a node with one or two free dofs)."""
    nodes, el, idx = square_net(1.0, 0.6, 0.1)
    x, z = nodes[:, 0], nodes[:, 2]
    fixed = np.repeat(((x < 1e-9) | (x > 1 - 1e-9) | (z < 1e-9))[:, None], 3, axis=1)
    if partly_fixed:
        fixed[idx[3, 2], 1] = True
        fixed[idx[5, 4], [0, 2]] = True
    cable = SlidingCable(idx[:, -1], linear(3.0))
    return Net(nodes, fixed, el, [linear(2.0)], cables=[cable])


def _reference_csr(ns: NetSystem) -> sp.csr_matrix:
    """The free-dof pattern the slow way: every slot's dof (row, column), COO -> CSR."""
    rows, cols = [], []
    pairs = [(ns.bars.i, ns.bars.j)] + [(c.nodes[:-1], c.nodes[1:]) for c in ns.cables]
    for i, j in pairs:
        for a, b in ((i, i), (j, j), (i, j), (j, i)):
            r = 3 * a[:, None, None] + np.arange(3)[None, :, None]
            c = 3 * b[:, None, None] + np.arange(3)[None, None, :]
            rows.append(np.broadcast_to(r, (len(a), 3, 3)).ravel())
            cols.append(np.broadcast_to(c, (len(a), 3, 3)).ravel())
    for c in ns.cables:
        dof = (3 * c.nodes[:, None] + np.arange(3)).ravel()
        rows.append(np.repeat(dof, len(dof)))
        cols.append(np.tile(dof, len(dof)))
    every = 3 * np.arange(ns.n)[:, None] + np.arange(3)
    rows.append(np.repeat(every, 3, axis=1).ravel())
    cols.append(np.tile(every, 3).ravel())
    index = np.full(3 * ns.n, -1)
    index[ns.free] = np.arange(ns.pattern.size)
    r, c = index[np.concatenate(rows)], index[np.concatenate(cols)]
    keep = (r >= 0) & (c >= 0)
    size = ns.pattern.size
    return sp.csr_matrix((np.ones(keep.sum()), (r[keep], c[keep])), shape=(size, size))


@pytest.mark.parametrize("partly_fixed", [False, True])
def test_pattern_from_the_node_graph_equals_the_slot_by_slot_csr(partly_fixed):
    ns = NetSystem(_net(partly_fixed))
    p, ref = ns.pattern, _reference_csr(ns)
    ref.sum_duplicates()
    assert p.nnz == ref.nnz
    np.testing.assert_array_equal(p.indptr, ref.indptr)
    np.testing.assert_array_equal(p.cols, ref.indices)
    np.testing.assert_array_equal(p.rows, np.repeat(np.arange(p.size), np.diff(ref.indptr)))
    np.testing.assert_array_equal(p.transpose[p.transpose], np.arange(p.nnz))
    np.testing.assert_array_equal(p.rows[p.transpose], p.cols)
    np.testing.assert_array_equal(p.cols[p.diagonal], p.rows[p.diagonal])
    # each slot lands on its own (row, column): scattering ones counts the slots per entry
    np.testing.assert_array_equal(p.scatter(np.ones(len(p.keep))), ref.data)
    upper = p.symmetric_upper(np.arange(p.nnz, dtype=float)).toarray()
    full = p.csr(np.arange(p.nnz, dtype=float)).toarray()
    np.testing.assert_array_equal(upper, np.triu(0.5 * (full + full.T)))


def test_z_columns_of_the_node_blocks():
    ns = NetSystem(_net())
    p = ns.pattern
    dz = np.random.default_rng(0).normal(size=(ns.n, 3))
    data = p.assemble(np.zeros((len(ns.bars.i), 6)), np.zeros(p.cable_map.shape[1]), dz)
    dense = np.zeros((3 * ns.n, 3 * ns.n))
    for k in range(ns.n):
        dense[3 * k:3 * k + 3, 3 * k + 2] = -dz[k]
    np.testing.assert_array_equal(p.csr(data).toarray(), dense[np.ix_(ns.free, ns.free)])


def _shape_by_superlu(ns: NetSystem, b: np.ndarray, monkeypatch) -> np.ndarray:
    from solver import state

    monkeypatch.setattr(state, "PARDISO_MIN_DOFS", 10**9)
    try:
        return ns.membrane_shape(b)
    finally:
        monkeypatch.undo()


def test_membrane_shape_of_a_large_net_by_cholesky_equals_superlu(monkeypatch):
    sc = simple_scene(refine=2)  # 14k unknowns: the Cholesky path
    ns = NetSystem(sc.net)
    assert ns.pattern.size >= PARDISO_MIN_DOFS
    ns.loads = list(sc.loads_at(1.0))
    b = -evaluate(ns, np.zeros_like(ns.x0)).r
    v = ns.membrane_shape(b)
    ref = _shape_by_superlu(ns, b, monkeypatch)
    assert v is not None and ref is not None
    np.testing.assert_allclose(v, ref, rtol=0, atol=START * np.abs(ref).max())


def test_membrane_shape_of_a_large_net_hanging_on_nothing_is_none():
    """A strand between two free nodes joined to nothing else: its Laplacian is singular."""
    net = simple_scene(refine=2).net
    n = len(net.nodes)
    nodes = np.vstack([net.nodes, [[-1.0, 0.0, 0.0], [-2.0, 0.0, 0.0]]])
    fixed = np.concatenate([np.asarray(net.fixed_dofs), np.zeros((2, 3), bool)])
    el = np.vstack([net.elements, [[n, n + 1]]])
    ns = NetSystem(Net(nodes, fixed, el, net.laws))
    assert ns.pattern.size >= PARDISO_MIN_DOFS
    assert ns.membrane_shape(np.ones(ns.pattern.size)) is None


def test_ray_potential_equals_the_strand_pass():
    ns = NetSystem(_net())
    rng = np.random.default_rng(2)
    u, v = rng.normal(0, 0.01, ns.x0.shape), rng.normal(0, 0.01, ns.x0.shape)
    f = rng.normal(0, 1e-3, ns.x0.shape)
    along = ray_potential(ns, u, v, f)
    for s in (0.0, 1e-3, 0.3, 1.0, 2.5):
        ref = potential(ns, u + s * v, f)
        assert along(s) == pytest.approx(ref, rel=KERNEL, abs=KERNEL * abs(potential(ns, u, f)))
