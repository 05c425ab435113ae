"""A fixed sparse pattern of the tangent on the free degrees of freedom, computed once per net
topology (`shared_pattern`: nets of one topology share it within a process).

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

import hashlib
import threading
from collections import OrderedDict

import numpy as np
import scipy.sparse as sp

# the upper triangle of a symmetric 3 x 3 block, entry by entry, and where each of its nine
# entries (a, b) finds its value among those six
SYM_PAIRS = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))
SYM_INDEX = np.array([[0, 1, 2], [1, 3, 4], [2, 4, 5]])
# patterns kept per process for reuse by later nets of the same topology (`shared_pattern`),
# at most this many bytes of arrays in all: the simple scene's pattern takes 5 MB at 61 x 21
# nodes and 85 MB at 241 x 81 (`Pattern.nbytes`), so the nets a fit or a band sweeps over
# stay, and one of 481 x 161 nodes (about 4 x 85 MB) is not kept
SHARED_BYTES = 256 * 2**20


def pair_values(k: np.ndarray) -> np.ndarray:
    """Values (k, 4, 3, 3) of a two-node member of stiffness block k (k, 3, 3): +k, +k, -k, -k."""
    return np.stack([k, k, -k, -k], axis=1)


def _node_slots(bar_i: np.ndarray, bar_j: np.ndarray, cable_nodes: list[np.ndarray],
                n_nodes: int) -> tuple[list[np.ndarray], list[np.ndarray], list[str]]:
    """The node pairs (p, q) of every slot group, in slot order, and each group's kind (how
    its slots expand a pair: `_positions`)."""
    every = np.arange(n_nodes)
    p_parts: list[np.ndarray] = []
    q_parts: list[np.ndarray] = []
    kinds: list[str] = []

    def members(i: np.ndarray, j: np.ndarray) -> None:  # blocks ii, jj, ij, ji: (k, 4, 3, 3)
        p_parts.append(np.stack([i, j, i, j], axis=1))
        q_parts.append(np.stack([i, j, j, i], axis=1))
        kinds.append("member")

    members(bar_i, bar_j)
    for nodes in cable_nodes:
        members(nodes[:-1], nodes[1:])
        p_parts.append(np.repeat(nodes, len(nodes)).reshape(len(nodes), len(nodes)))
        q_parts.append(np.tile(nodes, len(nodes)).reshape(len(nodes), len(nodes)))
        kinds.append("dense")  # (s, a, t, b): the rows and columns of the cable's dofs
    p_parts.append(every)
    q_parts.append(every)
    kinds.append("node")
    return p_parts, q_parts, kinds


def _positions(kind: str, p: np.ndarray, e: np.ndarray, row_at: np.ndarray,
               row_free: np.ndarray, col_at: np.ndarray, col_free: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
    """(kept, CSR positions of the kept) slots of a group with node pairs (p, entry e), from
    the CSR start of every dof's row (row_at, n x 3) and every node entry's column offset
    per free dof (col_at, entries x 3): a broadcast sum, one array the size of the group."""
    if kind == "dense":  # pairs (s, t) -> slots (s, a, t, b)
        rows, rf = row_at[p[:, 0]][:, :, None, None], row_free[p[:, 0]][:, :, None, None]
        cols, cf = col_at[e][:, None], col_free[e][:, None]
    else:  # pairs (...) -> slots (..., a, b)
        rows, rf = row_at[p][..., :, None], row_free[p][..., :, None]
        cols, cf = col_at[e][..., None, :], col_free[e][..., None, :]
    keep = rf & cf
    return keep.ravel(), (rows + cols)[keep]


class Pattern:
    """CSR structure of the free-dof tangent and the scatter map of every value slot.

    Slots, in this order: strands (m x 36), then per cable its segments (x 36) and its dense
    block ((3 k)^2), then the diagonal block of every node (n x 9).

    Built from the node graph (one entry per node pair, ~1/36 of the slots): the free-dof
    CSR is that graph with every node entry widened to its column node's free dofs, so a
    slot's CSR position is its row's start, plus its node entry's offset in the row, plus
    its column's rank among that node's free dofs; no sort of the slots, no COO -> CSR
    conversion (CPU, 241 x 81 nodes: 0.41 -> 0.22 s; 481 x 161: 1.7 -> 1.0 s).
    """

    def __init__(self, n_nodes: int, free: np.ndarray, bar_i: np.ndarray, bar_j: np.ndarray,
                 cable_nodes: list[np.ndarray]) -> None:
        n = n_nodes
        p_parts, q_parts, kinds = _node_slots(bar_i, bar_j, cable_nodes, n)
        keys = np.concatenate([p.ravel().astype(np.int64) * n + q.ravel()
                               for p, q in zip(p_parts, q_parts, strict=True)])
        node_keys, inverse = np.unique(keys, return_inverse=True)
        erow, ecol = node_keys // n, node_keys % n
        fmask = free.reshape(n, 3)
        self.size = int(free.sum())
        index = np.full(3 * n, -1)
        index[free] = np.arange(self.size)
        rank = (np.cumsum(fmask, axis=1) - fmask).ravel()  # a dof's rank among its node's free
        width = fmask.sum(axis=1)[ecol]  # free columns of each node entry
        before = np.cumsum(width) - width
        node_ptr = np.concatenate([[0], np.cumsum(np.bincount(erow, minlength=n))])
        row_start = before[node_ptr[:-1]]  # every node has an entry: its diagonal block
        offset = before - row_start[erow]  # each node entry's first column within its row
        free_dofs = np.flatnonzero(free)
        row_len = np.bincount(erow, width, n).astype(np.int64)[free_dofs // 3]
        self.indptr = np.concatenate([[0], np.cumsum(row_len)])
        self.nnz = int(self.indptr[-1])

        row_at = np.where(fmask, self.indptr[:-1][np.maximum(index, 0)].reshape(n, 3), 0)
        col_at, col_free = offset[:, None] + rank.reshape(n, 3)[ecol], fmask[ecol]
        keep, slot, at = [], [], 0
        for p, kind in zip(p_parts, kinds, strict=True):
            k, pos = _positions(kind, p, inverse[at:at + p.size].reshape(p.shape), row_at,
                                fmask, col_at, col_free)
            keep.append(k)
            slot.append(pos)
            at += p.size
        self.keep, self.slot = np.concatenate(keep), np.concatenate(slot)

        self._entries(node_keys, n, width, offset, row_start[free_dofs // 3], row_len, rank,
                      index, fmask)
        self._triangles()
        self._maps(len(bar_i), len(self.keep), inverse[-n:], offset, rank, index)
        # the index arrays of the matrices built at every step, in scipy's own index type:
        # given int64, scipy checks their range and converts them at every construction (61 x
        # 21 net: 60 against 17 us a CSR matrix, ~20 matrices a solve)
        self._csr_index = (_index(self.cols), _index(self.indptr))
        self._upper_index = (_index(self.upper_indices), _index(self.upper_indptr))
        self._upper_csr_index = (_index(self.upper_cols), _index(self.upper_rows_indptr))

    def _entries(self, node_keys: np.ndarray, n: int, width: np.ndarray, offset: np.ndarray,
                 row_start: np.ndarray, row_len: np.ndarray, rank: np.ndarray,
                 index: np.ndarray, fmask: np.ndarray) -> None:
        """Rows, columns and mirror positions of the CSR entries, row by row: each free dof's
        row is its node row's widened entries (from row_start, row_len long)."""
        erow, ecol = node_keys // n, node_keys % n
        entry_cols = index.reshape(n, 3)[ecol][fmask[ecol]]
        entry_node = np.repeat(np.arange(len(node_keys)), width)
        src = np.arange(self.nnz) + np.repeat(row_start - self.indptr[:-1], row_len)
        self.rows = np.repeat(np.arange(self.size), row_len)
        self.cols = entry_cols[src]
        mirror = np.searchsorted(node_keys, ecol * n + erow)  # node entry (q, p) of (p, q)
        self.transpose = (self.indptr[self.cols] + offset[mirror[entry_node[src]]]
                          + rank[np.flatnonzero(fmask.ravel())[self.rows]])

    def _triangles(self) -> None:
        """Diagonal and upper-triangle selections: the upper triangle in CSC order (column,
        then row) is the lower triangle's CSR order mirrored."""
        self.diagonal = np.flatnonzero(self.rows == self.cols)
        lower = np.flatnonzero(self.rows >= self.cols)
        self.upper = self.transpose[lower]
        self.upper_transpose = lower  # each upper entry's mirror
        self.upper_indices = self.cols[lower]
        self.upper_indptr = np.concatenate(
            [[0], np.cumsum(np.bincount(self.rows[lower], minlength=self.size))])
        self.upper_rows = np.flatnonzero(self.rows <= self.cols)  # CSR order: row, then column
        self.upper_cols = self.cols[self.upper_rows]
        self.upper_mirror = self.transpose[self.upper_rows]
        self.upper_rows_indptr = np.concatenate(
            [[0], np.cumsum(np.bincount(self.rows[self.upper_rows], minlength=self.size))])

    def _maps(self, m: int, n_slots: int, diagonal_entry: np.ndarray, offset: np.ndarray,
              rank: np.ndarray, index: np.ndarray) -> None:
        """The scatter as sparse operators: the upper triangles (m, 6) of the strands'
        symmetric blocks k -> CSR data in one product (each strand's four blocks +k, +k,
        -k, -k; each row sums its strands from the last to the first, as the product of
        the slot operator and the expansion did), the cables' slots -> CSR data; and the
        CSR positions of the node diagonal blocks' z columns (the hydrostatic load's
        z-derivative)."""
        n = len(diagonal_entry)
        n_cable = n_slots - 36 * m - 9 * n
        strand = np.flatnonzero(self.keep[:36 * m])
        k = len(strand)  # grouped by position, later strands first: a counting sort (CSR ->
        # CSC keeps the row order within a column) of the strand slots in reverse order
        by_slot = sp.csr_matrix((np.ones(k), self.slot[:k][::-1], np.arange(k + 1)),
                                shape=(k, self.nnz)).tocsc()
        order = strand[k - 1 - by_slot.indices]
        sign = np.repeat([1.0, 1.0, -1.0, -1.0], 9)  # slot (e, block, a, b) of strand e
        strand_of, within = np.divmod(order, 36)
        src = strand_of * 6 + np.tile(SYM_INDEX.ravel(), 4)[within]
        self.strand_map = sp.csr_matrix((sign[within], src, by_slot.indptr),
                                        shape=(self.nnz, 6 * m))
        cable = np.flatnonzero(self.keep[36 * m:36 * m + n_cable])
        self.cable_map = sp.csr_matrix(
            (np.ones(len(cable)), (self.slot[len(strand):len(strand) + len(cable)], cable)),
            shape=(self.nnz, n_cable))
        every = np.arange(n)  # (node, a): row 3 node + a, column 3 node + 2
        z_row, z_col = index[3 * every[:, None] + np.arange(3)].ravel(), index[3 * every + 2]
        self.z_take = np.flatnonzero((z_row >= 0) & (z_col.repeat(3) >= 0))
        node = self.z_take // 3
        self.z_slots = (self.indptr[z_row[self.z_take]] + offset[diagonal_entry[node]]
                        + rank[3 * node + 2])

    def nbytes(self) -> int:
        """Bytes of the arrays and sparse operators this pattern holds."""
        total = 0
        for value in vars(self).values():
            parts = value if isinstance(value, tuple) else (value,)
            for part in parts:
                if isinstance(part, np.ndarray):
                    total += part.nbytes
                elif sp.issparse(part):
                    total += sum(getattr(part, k).nbytes for k in ("data", "indices", "indptr"))
        return total

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
        return sp.csr_matrix((data, *self._csr_index), shape=(self.size, self.size))

    def symmetric_upper(self, data: np.ndarray) -> sp.csc_matrix:
        """Upper triangle (CSC) of the symmetric part (A + A^T) / 2 of the matrix `data`."""
        sym = 0.5 * (data[self.upper] + data[self.upper_transpose])
        return sp.csc_matrix((sym, *self._upper_index), shape=(self.size, self.size))

    def symmetric_upper_csr(self, data: np.ndarray) -> sp.csr_matrix:
        """The same upper triangle in CSR (what MKL PARDISO reads for a symmetric matrix)."""
        sym = 0.5 * (data[self.upper_rows] + data[self.upper_mirror])
        return sp.csr_matrix((sym, *self._upper_csr_index), shape=(self.size, self.size))


def _index(a: np.ndarray) -> np.ndarray:
    """`a` as scipy's index type for it: int32 when its values fit, else int64."""
    small = a.size == 0 or int(a.max()) < np.iinfo(np.int32).max
    return a.astype(np.int32 if small else np.int64)


# the shared patterns by topology, each with a dict its users keep derived objects in
# (`shared_extras`), dropped with it
_shared: OrderedDict[bytes, tuple[Pattern, dict, int]] = OrderedDict()  # + its nbytes()
_shared_lock = threading.Lock()


def shared_pattern(n_nodes: int, free: np.ndarray, bar_i: np.ndarray, bar_j: np.ndarray,
                   cable_nodes: list[np.ndarray]) -> Pattern:
    """The Pattern of this topology (node count, free dofs, strand node pairs, cables' node
    sequences), built once per process and shared by every later net of the same topology:
    a Pattern depends on nothing else and is only read once built. A band's variants, a
    fit's trials and repeated solves of one net differ in geometry, laws or loads, not in
    topology. Least recently used patterns go first once SHARED_BYTES are held."""
    digest = hashlib.blake2b(digest_size=20)  # 160 bits: a collision is out of reach
    for a in (np.asarray(n_nodes), free, bar_i, bar_j, *cable_nodes):
        arr = np.ascontiguousarray(a, dtype=np.int64 if a.dtype.kind in "iu" else a.dtype)
        digest.update(np.asarray(arr.shape, dtype=np.int64).tobytes())  # parts' boundaries
        digest.update(arr.dtype.str.encode())
        digest.update(arr.tobytes())
    key = digest.digest()
    with _shared_lock:
        found = _shared.get(key)
        if found is not None:
            _shared.move_to_end(key)
            return found[0]
    pattern = Pattern(n_nodes, free, bar_i, bar_j, cable_nodes)
    size = pattern.nbytes()
    with _shared_lock:
        if size <= SHARED_BYTES:
            _shared[key] = (pattern, {}, size)
            while sum(entry[2] for entry in _shared.values()) > SHARED_BYTES:
                _shared.popitem(last=False)
    return pattern


def shared_extras(pattern: Pattern) -> dict | None:
    """The dict kept with `pattern` while it is shared (`shared_pattern`), for objects that
    depend on the pattern alone (the solver's spare factorization handles); None when the
    pattern is not kept. Their bytes do not count towards SHARED_BYTES."""
    with _shared_lock:
        return next((extras for p, extras, _ in _shared.values() if p is pattern), None)


def clear_shared() -> None:
    """Forget the shared patterns and their extras (a benchmark's cold solve; tests)."""
    with _shared_lock:
        _shared.clear()
