"""A fixed sparse pattern of the tangent on the free degrees of freedom, computed once per net.

Every Newton step has the same non-zero positions: the 3 x 3 node blocks of each strand and
each sliding-cable segment, the dense block of each cable (all its nodes share one tension),
and the diagonal block of every node (the hydrostatic load's z-derivative). The pattern keeps,
for every value a step produces (in a fixed order), its position in the CSR data array, so a
step assembles its matrix with one `np.bincount`: no COO -> CSR conversion, no sorting.
Slack strands simply contribute zeros. The pattern is symmetric, so the symmetric part of a
matrix is a permutation of its data, and its upper triangle (what an LDL^T factorization
reads) a fixed selection.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

# the upper triangle of a symmetric 3 x 3 block, entry by entry, and where each of its nine
# entries (a, b) finds its value among those six
SYM_PAIRS = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))
SYM_INDEX = np.array([[0, 1, 2], [1, 3, 4], [2, 4, 5]])


def pair_values(k: np.ndarray) -> np.ndarray:
    """Values (k, 4, 3, 3) of a two-node member of stiffness block k (k, 3, 3): +k, +k, -k, -k."""
    return np.stack([k, k, -k, -k], axis=1)


def _block_slots(blocks: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(block, p, q) of every entry of the 3 x 3 blocks `blocks`, block by block, row-major."""
    pq = np.arange(9)
    return (np.repeat(blocks, 9), np.tile(pq // 3, len(blocks)), np.tile(pq % 3, len(blocks)))


def _strand_map(position: np.ndarray, m: int, nnz: int) -> sp.csc_matrix:
    """The (nnz, 6 m) operator: strands' upper triangles (in reverse, last strand's last value
    first: `assemble` reverses its input) -> CSR data, given each strand slot's CSR position
    (-1: not kept). Built as the CSR of its transpose, one row per strand value, so no sort:
    its product sums each CSR entry's strands last strand first, as the product of the slot
    matrix with the expansion did before (the same tangent bit for bit)."""
    sym = np.tile(SYM_INDEX.ravel(), 4)  # slot (block, a, b) of a strand -> its upper value
    sign = np.repeat([1.0, 1.0, -1.0, -1.0], 9)
    local = np.argsort(-sym, kind="stable")  # a strand's 36 slots, its last value's first
    strands = np.arange(m)[::-1, None]
    at = position[(36 * strands + local[None, :]).ravel()]
    kept = at >= 0
    value = (6 * m - 1 - 6 * strands - sym[local][None, :]).ravel()[kept]  # ascending
    transpose = sp.csr_matrix((np.tile(sign[local], m)[kept], at[kept], np.concatenate(
        [[0], np.cumsum(np.bincount(value, minlength=6 * m))])), shape=(6 * m, nnz))
    return transpose.T


class Pattern:
    """CSR structure of the free-dof tangent and the scatter map of every value slot.

    Slots, in this order: strands (m x 36), then per cable its segments (x 36) and its dense
    block ((3 k)^2), then the diagonal block of every node (n x 9).
    """

    def __init__(self, n_nodes: int, free: np.ndarray, bar_i: np.ndarray, bar_j: np.ndarray,
                 cable_nodes: list[np.ndarray]) -> None:
        # every slot as (3 x 3 node block, row p, column q); the blocks' node pairs (a, b)
        m, every = len(bar_i), np.arange(n_nodes)
        a_parts, b_parts = [bar_i, bar_j, bar_i, bar_j], [bar_i, bar_j, bar_j, bar_i]
        slot_parts = [_block_slots(np.arange(4 * m).reshape(4, m).T.ravel())]
        count = 4 * m
        for nodes in cable_nodes:
            s0, s1, k = nodes[:-1], nodes[1:], len(nodes)
            a_parts += [s0, s1, s0, s1, np.repeat(nodes, k)]
            b_parts += [s0, s1, s1, s0, np.tile(nodes, k)]
            slot_parts.append(_block_slots(count + np.arange(4 * (k - 1)).reshape(4, k - 1)
                                           .T.ravel()))
            count += 4 * (k - 1)
            dof = np.arange(3 * k)  # the dense block, row-major over the cable's dofs
            block = count + (dof[:, None] // 3) * k + dof[None, :] // 3
            slot_parts.append((block.ravel(), np.repeat(dof % 3, 3 * k), np.tile(dof % 3, 3 * k)))
            count += k * k
        a_parts.append(every)
        b_parts.append(every)
        slot_parts.append(_block_slots(count + every))
        slots = tuple(np.concatenate(x) for x in zip(*slot_parts))
        self._build(n_nodes, free, np.concatenate(a_parts), np.concatenate(b_parts), slots, m)

    def _build(self, n_nodes: int, free: np.ndarray, block_a: np.ndarray, block_b: np.ndarray,
               slots: tuple, m: int) -> None:
        """The CSR structure from the node blocks: node a's free rows all have the columns
        of a's block partners b (in node order), so an entry's CSR position is its row's
        start + the free dofs of a's partners before b + its column's rank within b. No
        sort over the dof entries (a sort over the node pairs only)."""
        index = np.full(3 * n_nodes, -1)
        self.size = int(free.sum())
        index[free] = np.arange(self.size)
        n_free = free.reshape(n_nodes, 3).sum(axis=1)
        first = np.concatenate([[0], np.cumsum(n_free)[:-1]])  # free dofs before each node
        pairs, inverse = np.unique(block_a.astype(np.int64) * n_nodes + block_b,
                                   return_inverse=True)
        pa, pb = pairs // n_nodes, pairs % n_nodes
        width = n_free[pb]  # columns each node pair gives its rows
        row_width = np.bincount(pa, width, n_nodes).astype(np.int64)
        before = np.cumsum(width) - width  # the partners' columns before b, in a's rows
        offset = before - (np.cumsum(row_width) - row_width)[pa]
        node, p, q = inverse[slots[0]], slots[1], slots[2]
        fr, fc = index[3 * pa[node] + p], index[3 * pb[node] + q]
        self.keep = (fr >= 0) & (fc >= 0)
        self.indptr = np.concatenate([[0], np.cumsum(row_width[np.flatnonzero(free) // 3])])
        fr, fc, node = fr[self.keep], fc[self.keep], node[self.keep]
        self.slot = self.indptr[fr] + offset[node] + fc - first[pb[node]]
        self.nnz = int(self.indptr[-1])
        self.rows, self.cols = np.empty(self.nnz, np.int64), np.empty(self.nnz, np.int64)
        self.rows[self.slot], self.cols[self.slot] = fr, fc
        at = np.empty(self.nnz, np.int64)
        at[self.slot] = node
        mirror = np.searchsorted(pairs, pb * n_nodes + pa)  # the node pattern is symmetric
        self.transpose = (self.indptr[self.cols] + offset[mirror[at]] + self.rows
                          - first[pa[at]])
        self._derived(n_nodes, index, m, len(p))

    def _derived(self, n_nodes: int, index: np.ndarray, m: int, n_slots: int) -> None:
        """The diagonal, the upper triangle's orders (CSC: the lower triangle's mirrors in
        CSR order) and the scatter maps."""
        self.diagonal = np.flatnonzero(self.rows == self.cols)
        lower = np.flatnonzero(self.rows >= self.cols)
        self.upper = self.transpose[lower]  # upper entries, column by column
        self.upper_transpose = lower
        self.upper_indices = self.cols[lower]
        self.upper_indptr = np.concatenate([[0], np.cumsum(np.bincount(
            self.rows[lower], minlength=self.size))])
        self.upper_rows = np.flatnonzero(self.rows <= self.cols)  # CSR order: row, then column
        self.upper_cols = self.cols[self.upper_rows]
        self.upper_mirror = self.transpose[self.upper_rows]
        self.upper_rows_indptr = np.concatenate(
            [[0], np.cumsum(np.bincount(self.rows[self.upper_rows], minlength=self.size))])
        # the same scatter as sparse operators: the upper triangles (m, 6) of the strands'
        # symmetric blocks k -> CSR data in one product (each strand's four blocks +k, +k,
        # -k, -k), the cables' slots -> CSR data; and the CSR positions of the node diagonal
        # blocks' z columns (the hydrostatic load's z-derivative)
        n_cable = n_slots - 36 * m - 9 * n_nodes
        kept = np.flatnonzero(self.keep)
        position = np.full(n_slots, -1)
        position[kept] = self.slot
        self.strand_map = _strand_map(position[:36 * m], m, self.nnz)
        cable = slice(*np.searchsorted(kept, [36 * m, 36 * m + n_cable]))  # kept is sorted
        self.cable_map = sp.csr_matrix((np.ones(cable.stop - cable.start), (
            self.slot[cable], kept[cable] - 36 * m)), shape=(self.nnz, n_cable))
        every = np.arange(n_nodes)
        dof = 3 * every[:, None] + np.arange(3)  # (node, a): row 3 node + a, column 3 node + 2
        z_row, z_col = index[dof].ravel(), index[3 * every + 2].repeat(3)
        self.z_take = np.flatnonzero((z_row >= 0) & (z_col >= 0))
        self.z_slots = position[n_slots - 9 * n_nodes + 3 * self.z_take + 2]

    def assemble(self, strand_upper: np.ndarray, cables: np.ndarray, dz: np.ndarray
                 ) -> np.ndarray:
        """CSR data of the strands' symmetric blocks, given by their upper triangles (m, 6)
        in SYM_PAIRS order, the cables' slot values (in slot order) and the node blocks' z
        columns -dz (n, 3): the same sum as `scatter`, without the (m, 4, 3, 3) copy."""
        data = self.strand_map @ strand_upper.ravel()[::-1]
        other = self.cable_map @ cables if cables.size else np.zeros(0)
        if other.size:
            other[self.z_slots] -= dz.ravel()[self.z_take]
            return data + other
        data[self.z_slots] -= dz.ravel()[self.z_take]
        return data

    def scatter(self, values: np.ndarray) -> np.ndarray:
        """CSR data (nnz,) of all slot values (in slot order; summed where they coincide)."""
        return np.bincount(self.slot, weights=values[self.keep], minlength=self.nnz)

    def csr(self, data: np.ndarray) -> sp.csr_matrix:
        return sp.csr_matrix((data, self.cols, self.indptr), shape=(self.size, self.size))

    def symmetric_upper(self, data: np.ndarray) -> sp.csc_matrix:
        """Upper triangle (CSC) of the symmetric part (A + A^T) / 2 of the matrix `data`."""
        sym = 0.5 * (data[self.upper] + data[self.upper_transpose])
        return sp.csc_matrix((sym, self.upper_indices, self.upper_indptr),
                             shape=(self.size, self.size))

    def symmetric_upper_csr(self, data: np.ndarray) -> sp.csr_matrix:
        """The same upper triangle in CSR (what MKL PARDISO reads for a symmetric matrix)."""
        sym = 0.5 * (data[self.upper_rows] + data[self.upper_mirror])
        return sp.csr_matrix((sym, self.upper_cols,
                              self.upper_rows_indptr), shape=(self.size, self.size))
