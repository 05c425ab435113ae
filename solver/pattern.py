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
        self.upper_transpose = self.transpose[self.upper]  # each upper entry's mirror
        self.upper_indices, self.upper_indptr = order.indices, order.indptr
        self.upper_rows = np.flatnonzero(self.rows <= self.cols)  # CSR order: row, then column
        self.upper_cols = self.cols[self.upper_rows]
        self.upper_mirror = self.transpose[self.upper_rows]
        self.upper_rows_indptr = np.concatenate(
            [[0], np.cumsum(np.bincount(self.rows[self.upper_rows], minlength=self.size))])

        # the same scatter as sparse operators: the upper triangles (m, 6) of the strands'
        # symmetric blocks k -> CSR data in one product (each strand's four blocks +k, +k,
        # -k, -k), the cables' slots -> CSR data; and the CSR positions of the node diagonal
        # blocks' z columns (the hydrostatic load's z-derivative)
        m, n_cable = len(bar_i), len(rows) - 36 * len(bar_i) - 9 * n_nodes
        kept = np.flatnonzero(self.keep)
        full = sp.csr_matrix((np.ones(len(kept)), (self.slot, kept)), shape=(self.nnz, len(rows)))
        sign = np.repeat([1.0, 1.0, -1.0, -1.0], 9)  # slot (e, block, a, b) of strand e
        src = (np.arange(m)[:, None] * 6 + np.tile(SYM_INDEX.ravel(), 4)[None, :]).ravel()
        expand = sp.csr_matrix((np.tile(sign, m), (np.arange(36 * m), src)), shape=(36 * m, 6 * m))
        self.strand_map = (full[:, :36 * m] @ expand).tocsr()
        self.cable_map = full[:, 36 * m:36 * m + n_cable].tocsr()
        dof = 3 * every[:, None] + np.arange(3)  # (node, a): row 3 node + a, column 3 node + 2
        z_row, z_col = index[dof].ravel(), index[3 * every + 2].repeat(3)
        self.z_take = np.flatnonzero((z_row >= 0) & (z_col >= 0))
        self.z_slots = np.searchsorted(uniq, z_row[self.z_take].astype(np.int64) * self.size
                                       + z_col[self.z_take])

    def assemble(self, strand_upper: np.ndarray, cables: np.ndarray, dz: np.ndarray
                 ) -> np.ndarray:
        """CSR data of the strands' symmetric blocks, given by their upper triangles (m, 6)
        in SYM_PAIRS order, the cables' slot values (in slot order) and the node blocks' z
        columns -dz (n, 3): the same sum as `scatter`, without the (m, 4, 3, 3) copy."""
        data = self.strand_map @ strand_upper.ravel()
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
