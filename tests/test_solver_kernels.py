"""The fast path's per-iteration kernels against the plain formulas they replace: the laws'
one-pass evaluation, the strand pass and the tangent scattered into the fixed pattern (upper
triangles of the strand blocks, hydrostatic z columns) against the reference COO assembly,
the backward-error norm, at random states of a net with interleaved laws, slack and taut
strands, a sliding cable and a follower load."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from solver import Hydrostatic, Net, SlidingCable, linear, piecewise
from solver.assemble import internal, strain_energy
from solver.linsolve import row_sum_norm
from solver.scenes import square_net
from solver.state import NetSystem, evaluate, potential, tangent_values

KERNEL = 1e-14  # relative: the same products and sums, only reassociated (BLAS, bincount)
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
        assert potential(ns, u, st.f) == pytest.approx(st.potential(st.f), rel=KERNEL)
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
