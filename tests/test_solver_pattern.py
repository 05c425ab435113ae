"""The tangent pattern against its plain construction, array for array and bit for bit: the
slots' CSR positions found by sorting (scipy's COO -> CSR), the upper triangle and the
transpose by searching those positions, the strands' operator by a stable sort of the slots,
the damping by `scatter`. The pattern builds what a solve reads from the node graph instead;
the same arrays in the same order mean the same sums, factor order and answers. Nets: a
square one with rollers and a sliding cable, a diamond one with a cable, one with doubled
and reversed strands and two cables, a cable without strands, simple-pinned 61 x 21."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from test_solver_kernels import _net, _partly_fixed_net, _slot_rows_cols

from printgen.solver import Net, SlidingCable, linear
from printgen.solver.pattern import SYM_INDEX, pair_values
from printgen.solver.scenes import simple_scene
from printgen.solver.state import NetSystem


def _diamond_net() -> Net:
    """A diamond net (strands at +-45 degrees) on a 9 x 7 grid, held on three sides, its top
    row threaded on a sliding cable."""
    nx, nz = 9, 7
    ix, iz = np.meshgrid(np.arange(nx), np.arange(nz), indexing="ij")
    on = (ix + iz) % 2 == 0
    number = np.full((nx, nz), -1)
    number[on] = np.arange(int(on.sum()))
    nodes = np.column_stack([ix[on] * 0.1, np.zeros(int(on.sum())), iz[on] * 0.1])
    el = []
    for dz in (1, -1):
        a = number[:-1, max(0, -dz):nz - max(0, dz)]
        b = number[1:, max(0, dz):nz - max(0, -dz)]
        keep = (a >= 0) & (b >= 0)
        el.append(np.column_stack([a[keep], b[keep]]))
    x, z = nodes[:, 0], nodes[:, 2]
    fixed = (x < 1e-9) | (x > 0.8 - 1e-9) | (z < 1e-9)
    top = number[:, -1][number[:, -1] >= 0]
    return Net(nodes, fixed, np.vstack(el), [linear(1.0)],
               cables=[SlidingCable(top, linear(2.0))])


def _doubled_net() -> Net:
    """The rollers net with some strands twice and some reversed (i > j), and two cables."""
    base = _partly_fixed_net()
    el = np.asarray(base.elements)
    return Net(base.nodes, base.fixed_dofs, np.vstack([el, el[::7], el[3::5, ::-1]]),
               [linear(1.0)], cables=[base.cables[0], SlidingCable(np.arange(5, 15),
                                                                   linear(2.0))])


def _cable_only_net() -> Net:
    nodes = np.array([[0.0, 0, 0], [0.5, 0, -0.1], [1.0, 0, 0]])
    return Net(nodes, np.array([True, False, True]), np.zeros((0, 2), int), [linear(1.0)],
               cables=[SlidingCable(np.array([0, 1, 2]), linear(1.0))])


NETS = {"square": lambda: _net()[0], "rollers": _partly_fixed_net, "diamond": _diamond_net,
        "doubled": _doubled_net, "cable only": _cable_only_net,
        "simple 61 x 21": lambda: simple_scene(refine=1).net}


def _plain(ns: NetSystem) -> dict:
    """The pattern's arrays by the plain construction (see the module's docstring)."""
    rows, cols = _slot_rows_cols(ns)
    index = np.full(3 * ns.n, -1)
    index[ns.free] = np.arange(int(ns.free.sum()))
    keep = (index[rows] >= 0) & (index[cols] >= 0)
    r, c = index[rows[keep]], index[cols[keep]]
    size = int(ns.free.sum())
    csr = sp.coo_matrix((np.ones(len(r)), (r, c)), shape=(size, size)).tocsr()
    csr.sum_duplicates()
    entry_rows = np.repeat(np.arange(size), np.diff(csr.indptr))
    linear_at = entry_rows * size + csr.indices  # ascending: the CSR order
    slot = np.searchsorted(linear_at, r * size + c)
    transpose = np.searchsorted(linear_at, csr.indices * size + entry_rows)
    lower = np.flatnonzero(entry_rows >= csr.indices)
    out = {"indptr": csr.indptr, "cols": csr.indices, "rows": entry_rows, "keep": keep,
           "slot": slot, "transpose": transpose,
           "diagonal": np.flatnonzero(entry_rows == csr.indices), "upper": transpose[lower],
           "upper_transpose": lower, "upper_indices": csr.indices[lower],
           "upper_indptr": np.concatenate([[0], np.cumsum(np.bincount(entry_rows[lower],
                                                                      minlength=size))])}
    m = len(ns.bars.rest)
    strand = np.flatnonzero(keep[:36 * m])  # each position's strands, the last one first
    order = strand[::-1][np.argsort(slot[:len(strand)][::-1], kind="stable")]
    e, within = np.divmod(order, 36)
    out["strand_map"] = sp.csr_matrix(
        (np.repeat([1.0, 1.0, -1.0, -1.0], 9)[within], 6 * e + np.tile(SYM_INDEX.ravel(), 4)[
            within], np.concatenate([[0], np.cumsum(np.bincount(slot[:len(strand)],
                                                                minlength=csr.nnz))])),
        shape=(csr.nnz, 6 * m))
    n_cable = len(keep) - 36 * m - 9 * ns.n
    cable = np.flatnonzero(keep[36 * m:36 * m + n_cable])
    out["cable_map"] = sp.csr_matrix(
        (np.ones(len(cable)), (slot[len(strand):len(strand) + len(cable)], cable)),
        shape=(csr.nnz, n_cable))
    eye = np.eye(3)[None]  # the damping: the members' w I3 blocks, w = 1 / rest length
    values = [pair_values((1.0 / ns.bars.rest)[:, None, None] * eye).ravel()]
    for cab in ns.cables:
        values.append(pair_values((1.0 / cab.l0)[:, None, None] * eye).ravel())
        values.append(np.zeros((3 * len(cab.nodes)) ** 2))
    values.append(np.zeros(9 * ns.n))
    data = np.bincount(slot, np.concatenate(values)[keep], csr.nnz)
    out["damping"] = data / ((float(data[out["diagonal"]].mean()) if size else 1.0) or 1.0)
    node_dofs = index.reshape(ns.n, 3)  # the node blocks' z columns: (node, a) -> (node, z)
    z_row, z_col = node_dofs.ravel(), np.repeat(node_dofs[:, 2], 3)
    out["z_take"] = np.flatnonzero((z_row >= 0) & (z_col >= 0))
    out["z_slots"] = np.searchsorted(linear_at, z_row[out["z_take"]] * size
                                     + z_col[out["z_take"]])
    return out


def _bitwise(name: str, got, expected) -> None:
    if sp.issparse(expected):
        assert got.shape == expected.shape, name
        for part in ("indptr", "indices", "data"):
            _bitwise(f"{name}.{part}", getattr(got, part), getattr(expected, part))
        return
    got, expected = np.asarray(got), np.asarray(expected)
    assert got.shape == expected.shape, name
    np.testing.assert_array_equal(got, expected, err_msg=name)
    assert got.tobytes() == expected.astype(got.dtype).tobytes(), name  # -0.0 vs 0.0 too


@pytest.mark.parametrize("name", list(NETS))
def test_pattern_equals_its_plain_construction_bit_for_bit(name):
    ns = NetSystem(NETS[name]())
    p, plain = ns.pattern, _plain(ns)
    assert (p.size, p.nnz) == (int(ns.free.sum()), len(plain["cols"]))
    for key, expected in plain.items():
        got = ns.damping if key == "damping" else getattr(p, key)
        _bitwise(key, got, expected)
    assert p.strand_map.nnz == int(plain["keep"][:36 * len(ns.bars.rest)].sum())
    rng = np.random.default_rng(7)  # the step's matrices, from the same arrays
    data = rng.normal(size=p.nnz)
    sym = 0.5 * (data[plain["upper"]] + data[plain["upper_transpose"]])
    _bitwise("symmetric_upper", p.symmetric_upper(data).data, sym)
    upper_rows = np.flatnonzero(plain["rows"] <= plain["cols"])
    _bitwise("symmetric_upper_csr", p.symmetric_upper_csr(data).data,
             0.5 * (data[upper_rows] + data[plain["transpose"][upper_rows]]))


def test_a_solve_builds_no_slot_positions(monkeypatch):
    """What only `scatter`, the tests and PARDISO read is built when first asked for: a
    solve on the default backends leaves it unbuilt; asked for, it is the plain one."""
    from collections import OrderedDict

    from printgen.solver import pattern as pattern_module
    from printgen.solver import solve

    monkeypatch.setattr(pattern_module, "_shared", OrderedDict())  # this test's own pattern
    scene = simple_scene(refine=1)
    ns = NetSystem(scene.net)
    res = solve(scene.net, scene.loads_at(1.0))
    assert res.converged and res.backend in ("ldl", "lu")
    lazy = {"_slots", "transpose", "rows", "_upper_csr"}
    assert not lazy & set(vars(ns.pattern))
    plain = _plain(ns)
    for key in ("keep", "slot", "transpose", "rows"):
        _bitwise(key, getattr(ns.pattern, key), plain[key])
    assert lazy - {"_upper_csr"} <= set(vars(ns.pattern))
