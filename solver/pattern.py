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


def block_rows_cols(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Dof rows and columns (k, 3, 3) of the 3 x 3 blocks at node pairs (a, b)."""
    r = 3 * a[:, None, None] + np.arange(3)[None, :, None]
    c = 3 * b[:, None, None] + np.arange(3)[None, None, :]
    return np.broadcast_to(r, (len(a), 3, 3)), np.broadcast_to(c, (len(a), 3, 3))


def pair_rows_cols(i: np.ndarray, j: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows and columns (k, 4, 3, 3) of the blocks ii, jj, ij, ji of two-node members."""
    rc = [block_rows_cols(a, b) for a, b in ((i, i), (j, j), (i, j), (j, i))]
    return np.stack([r for r, _ in rc], axis=1), np.stack([c for _, c in rc], axis=1)


def pair_values(k: np.ndarray) -> np.ndarray:
    """Values (k, 4, 3, 3) of a two-node member of stiffness block k (k, 3, 3): +k, +k, -k, -k."""
    return np.stack([k, k, -k, -k], axis=1)


class Pattern:
    """CSR structure of the free-dof tangent and the scatter map of every value slot.

    Slots, in this order: strands (m x 36), then per cable its segments (x 36) and its dense
    block ((3 k)^2), then the diagonal block of every node (n x 9).
    """

    def __init__(self, n_nodes: int, free: np.ndarray, bar_i: np.ndarray, bar_j: np.ndarray,
                 cable_nodes: list[np.ndarray]) -> None:
        row_parts: list[np.ndarray] = []
        col_parts: list[np.ndarray] = []

        def add(r: np.ndarray, c: np.ndarray) -> None:
            row_parts.append(r.ravel())
            col_parts.append(c.ravel())

        add(*pair_rows_cols(bar_i, bar_j))
        for nodes in cable_nodes:
            add(*pair_rows_cols(nodes[:-1], nodes[1:]))
            dof = (3 * nodes[:, None] + np.arange(3)).ravel()
            add(np.repeat(dof, len(dof)), np.tile(dof, len(dof)))
        every = np.arange(n_nodes)
        add(*block_rows_cols(every, every))
        rows, cols = np.concatenate(row_parts), np.concatenate(col_parts)
        index = np.full(3 * n_nodes, -1)
        index[free] = np.arange(int(free.sum()))
        fr, fc = index[rows], index[cols]
        self.keep = (fr >= 0) & (fc >= 0)
        self.size = int(free.sum())
        keys = fr[self.keep].astype(np.int64) * self.size + fc[self.keep]
        uniq, self.slot = np.unique(keys, return_inverse=True)
        self.nnz = len(uniq)
        self.rows, self.cols = uniq // self.size, uniq % self.size
        self.indptr = np.concatenate([[0], np.cumsum(np.bincount(self.rows,
                                                                 minlength=self.size))])
        self.transpose = np.searchsorted(uniq, self.cols * self.size + self.rows)
        self.diagonal = np.flatnonzero(self.rows == self.cols)
        upper = np.flatnonzero(self.rows <= self.cols)
        order = sp.csc_matrix((np.arange(len(upper), dtype=float) + 1,
                               (self.rows[upper], self.cols[upper])),
                              shape=(self.size, self.size))
        self.upper = upper[order.data.astype(np.int64) - 1]
        self.upper_indices, self.upper_indptr = order.indices, order.indptr
        self.upper_rows = np.flatnonzero(self.rows <= self.cols)  # CSR order: row, then column
        self.upper_cols = self.cols[self.upper_rows]
        self.upper_mirror = self.transpose[self.upper_rows]
        self.upper_rows_indptr = np.concatenate(
            [[0], np.cumsum(np.bincount(self.rows[self.upper_rows], minlength=self.size))])

        # the same scatter as sparse operators: strand blocks k (m, 3, 3) -> CSR data in one
        # product (each strand's four blocks +k, +k, -k, -k), and the other slots (cables,
        # node diagonals) -> CSR data
        m = len(bar_i)
        n_slot = len(rows)
        kept = np.flatnonzero(self.keep)
        full = sp.csr_matrix((np.ones(len(kept)), (self.slot, kept)), shape=(self.nnz, n_slot))
        sign = np.repeat([1.0, 1.0, -1.0, -1.0], 9)  # slot (e, block, a, b) of strand e
        src = (np.arange(m)[:, None] * 9 + np.tile(np.arange(9), 4)[None, :]).ravel()
        expand = sp.csr_matrix((np.tile(sign, m), (np.arange(36 * m), src)), shape=(36 * m, 9 * m))
        self.strand_map = (full[:, :36 * m] @ expand).tocsr()
        self.other_map = full[:, 36 * m:].tocsr()

    def assemble(self, strand_blocks: np.ndarray, others: np.ndarray) -> np.ndarray:
        """CSR data of strand blocks k (m, 3, 3) and the other slots' values (cables, node
        diagonals, in slot order): the same sum as `scatter`, without the (m, 4, 3, 3) copy."""
        return self.strand_map @ strand_blocks.ravel() + self.other_map @ others

    def scatter(self, values: np.ndarray) -> np.ndarray:
        """CSR data (nnz,) of all slot values (in slot order; summed where they coincide)."""
        return np.bincount(self.slot, weights=values[self.keep], minlength=self.nnz)

    def csr(self, data: np.ndarray) -> sp.csr_matrix:
        return sp.csr_matrix((data, self.cols, self.indptr), shape=(self.size, self.size))

    def symmetric_upper(self, data: np.ndarray) -> sp.csc_matrix:
        """Upper triangle (CSC) of the symmetric part (A + A^T) / 2 of the matrix `data`."""
        sym = 0.5 * (data + data[self.transpose])
        return sp.csc_matrix((sym[self.upper], self.upper_indices, self.upper_indptr),
                             shape=(self.size, self.size))

    def symmetric_upper_csr(self, data: np.ndarray) -> sp.csr_matrix:
        """The same upper triangle in CSR (what MKL PARDISO reads for a symmetric matrix)."""
        sym = 0.5 * (data[self.upper_rows] + data[self.upper_mirror])
        return sp.csr_matrix((sym, self.upper_cols,
                              self.upper_rows_indptr), shape=(self.size, self.size))
