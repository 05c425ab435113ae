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
from functools import cached_property

import numpy as np
import scipy.sparse as sp

# the upper triangle of a symmetric 3 x 3 block, entry by entry, and where each of its nine
# entries (a, b) finds its value among those six
SYM_PAIRS = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))
SYM_INDEX = np.array([[0, 1, 2], [1, 3, 4], [2, 4, 5]])
_XYZ = np.arange(3, dtype=np.int8)  # a dof's direction, in a byte
_INT32_MAX = int(np.iinfo(np.int32).max)
_PAIR_SIGN = np.array([1.0, 1.0, -1.0, -1.0])  # a member's blocks ii, jj, ij, ji: +k, +k, -k, -k
# patterns kept per process for reuse by later nets of the same topology (`shared_pattern`),
# at most this many bytes of arrays in all: the simple scene's pattern takes 3.3 MB at 61 x
# 21 nodes, 56 MB at 241 x 81 and 226 MB at 481 x 161 (`Pattern.nbytes` as built), so the
# nets a fit or a band sweeps over stay (three of 241 x 81), and one of 481 x 161 is not kept
SHARED_BYTES = 192 * 2**20


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


def _unique(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """np.unique(keys, return_inverse=True), by a stable sort: the keys come in sorted
    runs (a member's node pairs in member order), which a merge sort takes as they are (61
    x 21 nodes: a sixth of the quicksort's time)."""
    order = np.argsort(keys, kind="stable")
    ordered = keys[order]
    new = np.ones(len(keys), bool)
    np.not_equal(ordered[1:], ordered[:-1], out=new[1:])
    inverse = np.empty(len(keys), np.intp)
    inverse[order] = np.cumsum(new) - 1
    return ordered[new], inverse


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
    conversion (CPU, 241 x 81 nodes: 0.41 -> 0.22 s; 481 x 161: 1.7 -> 1.0 s). What every
    solve reads is built from the node entries as well (the strands' operator from each
    node entry's strands, the damping from each node entry's sums), without the slots'
    positions: those (`slot`, `keep`, what `scatter` reads), the whole transpose map and
    the upper triangle in CSR (PARDISO's) are built when first asked for.
    """

    def __init__(self, n_nodes: int, free: np.ndarray, bar_i: np.ndarray, bar_j: np.ndarray,
                 cable_nodes: list[np.ndarray]) -> None:
        n = n_nodes
        p_parts, q_parts, kinds = _node_slots(bar_i, bar_j, cable_nodes, n)
        keys = np.concatenate([p.ravel().astype(np.int64) * n + q.ravel()
                               for p, q in zip(p_parts, q_parts, strict=True)])
        node_keys, inverse = _unique(keys)
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

        groups, at = [], 0  # each slot group's kind, node pairs and their node entries
        for p, kind in zip(p_parts, kinds, strict=True):
            groups.append((kind, p, inverse[at:at + p.size].reshape(p.shape)))
            at += p.size
        self._slot_parts = (groups, index, fmask, offset, rank, ecol)
        self._node_ptr = node_ptr  # each node's first node entry (they come row by row)
        self._mirror_parts = (np.searchsorted(node_keys, ecol * n + erow), offset, rank,
                              free_dofs)  # node entry (q, p) of each (p, q)
        entry, sym = self._entries(n, ecol, width, row_start[free_dofs // 3], row_len, index,
                                   fmask)
        # each free dof's diagonal entry: its row's start, plus its node block's offset in
        # the row, plus its rank among its node's free dofs
        self.diagonal = self.indptr[:-1] + offset[inverse[-n:]][free_dofs // 3] + rank[free_dofs]
        self._triangles(entry, rank[free_dofs])
        # the node entries of the strands' blocks, then of every cable's segments'
        members = [e for kind, _, e in groups if kind == "member"]
        self._members = (members[0] if len(members) == 1 else np.concatenate(members),
                         len(node_keys))
        self._maps(len(bar_i), entry, sym, len(node_keys), inverse[-n:], offset, rank, index)
        # the index arrays of the matrices built at every step, in scipy's own index type:
        # given int64, scipy checks their range and converts them at every construction (61 x
        # 21 net: 60 against 17 us a CSR matrix, ~20 matrices a solve)
        self._csr_index = (self.cols, _index(self.indptr))
        self._upper_index = (self.upper_indices, _index(self.upper_indptr))

    def _entries(self, n: int, ecol: np.ndarray, width: np.ndarray, row_start: np.ndarray,
                 row_len: np.ndarray, index: np.ndarray, fmask: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
        """Columns and node entries of the CSR entries, row by row: each free dof's row is
        its node row's widened entries (from row_start, row_len long). Returns the node
        entries as intp (what indexing reads without a conversion; `entry` keeps them in
        scipy's index type) and each entry's place in the symmetric 3 x 3 block of its node
        entry (`SYM_INDEX`), from the x, y or z of its row and column, in bytes."""
        src = np.arange(self.nnz) + np.repeat(row_start - self.indptr[:-1], row_len)
        free_cols = fmask[ecol]  # which columns of each node entry are free
        self.cols = _index(index.reshape(n, 3)[ecol][free_cols], self.size)[src]
        entry = np.repeat(np.arange(len(ecol)), width)[src]
        self.entry = _index(entry, len(ecol))
        a = np.repeat((self._mirror_parts[3] % 3).astype(np.int8), row_len)
        b = np.broadcast_to(_XYZ, free_cols.shape)[free_cols][src]
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        self._block_diagonal = np.flatnonzero(a == b)  # on their node block's diagonal
        return entry, lo * (5 - lo) // 2 + hi  # SYM_INDEX[a, b]: 0, 1, 2 / 3, 4 / 5

    def node_adjacency(self) -> tuple[np.ndarray, np.ndarray]:
        """The graph of the nodes that have a free dof, as CSR (xadj, adjncy; no self-loops,
        nodes numbered in the order of their dofs): two nodes adjacent where the tangent
        couples them (a strand, a cable's segment or dense block). What a nested-dissection
        ordering of the tangent reads: a ninth of the dof graph's entries."""
        fmask, ecol = self._slot_parts[2], self._slot_parts[5]
        has: np.ndarray = np.asarray(fmask.any(axis=1))
        rank = np.cumsum(has) - 1
        erow = np.repeat(np.arange(len(has)), np.diff(self._node_ptr))
        keep = has[erow] & has[ecol] & (erow != ecol)
        count = np.bincount(rank[erow[keep]], minlength=int(has.sum()))
        return np.concatenate([[0], np.cumsum(count)]), rank[ecol[keep]]

    def dof_order(self, node_order: np.ndarray) -> np.ndarray:
        """The free dofs node by node, the nodes in `node_order` (numbered as in
        `node_adjacency`), each node's dofs in their own order."""
        width = self._slot_parts[2].sum(axis=1)
        width = width[width > 0]
        first = np.cumsum(width) - width
        take = width[node_order]
        return (np.repeat(first[node_order], take) + np.arange(int(take.sum()))
                - np.repeat(np.cumsum(take) - take, take))

    @cached_property
    def rows(self) -> np.ndarray:
        """The row of every CSR entry."""
        return np.repeat(np.arange(self.size), np.diff(self.indptr))

    def _mirrors(self, at: np.ndarray | slice) -> np.ndarray:
        """CSR positions of the mirrors (column, row) of the CSR entries `at`."""
        mirror, offset, rank, free_dofs = self._mirror_parts
        return (self.indptr[self.cols[at]] + offset[mirror[self.entry[at]]]
                + rank[free_dofs[self.rows[at]]])

    @cached_property
    def row_starts(self) -> np.ndarray:
        """The CSR start of every row that has entries (what `linsolve.row_sum_norm` reduces
        at: the pattern's alone, so computed once, not at every solve)."""
        return self.indptr[:-1][np.diff(self.indptr) > 0]

    @cached_property
    def transpose(self) -> np.ndarray:
        """The CSR position of every entry's mirror."""
        return self._mirrors(slice(None))

    def _triangles(self, entry: np.ndarray, row_rank: np.ndarray) -> None:
        """Upper-triangle selections: the upper triangle in CSC order (column, then row) is
        the lower triangle's CSR order mirrored, and a row's lower triangle is its entries
        up to its diagonal (its columns ascend). row_rank: each row's dof's rank among its
        node's free dofs; entry: each CSR entry's node entry."""
        count = self.diagonal - self.indptr[:-1] + 1
        self.upper_indptr = np.concatenate([[0], np.cumsum(count)])
        lower = np.arange(self.upper_indptr[-1]) + np.repeat(
            self.indptr[:-1] - self.upper_indptr[:-1], count)
        self.upper_transpose = lower  # each upper entry's mirror
        self.upper_indices = self.cols[lower]
        mirror, offset, _, _ = self._mirror_parts
        self.upper = (self.indptr[self.upper_indices] + offset[mirror[entry[lower]]]
                      + np.repeat(row_rank, count))

    @cached_property
    def _upper_csr(self) -> tuple[np.ndarray, np.ndarray, tuple[np.ndarray, np.ndarray]]:
        """The upper triangle in CSR order (row, then column): its entries, their mirrors
        and its index arrays."""
        rows = np.flatnonzero(self.rows <= self.cols)
        indptr = np.concatenate(
            [[0], np.cumsum(np.bincount(self.rows[rows], minlength=self.size))])
        return rows, self._mirrors(rows), (_index(self.cols[rows]), _index(indptr))

    def _maps(self, m: int, entry: np.ndarray, sym: np.ndarray, n_entries: int,
              diagonal_entry: np.ndarray, offset: np.ndarray, rank: np.ndarray,
              index: np.ndarray) -> None:
        """The scatter as sparse operators: the upper triangles (m, 6) of the strands'
        symmetric blocks k -> CSR data in one product (each strand's four blocks +k, +k,
        -k, -k; each row sums its strands from the last to the first, as the product of
        the slot operator and the expansion did), the cables' slots -> CSR data; and the
        CSR positions of the node diagonal blocks' z columns (the hydrostatic load's
        z-derivative)."""
        n = len(diagonal_entry)
        self.strand_map = self._strand_map(m, entry, sym, n_entries)
        groups = self._slot_parts[0][1:-1]  # the cables' segments and dense blocks
        if groups:
            keep, slot = zip(*(self._group_slots(g) for g in groups), strict=True)
            cable = np.flatnonzero(np.concatenate(keep))
            self.cable_map = sp.csr_matrix(
                (np.ones(len(cable)), (np.concatenate(slot), cable)),
                shape=(self.nnz, sum(len(k) for k in keep)))
        else:
            self.cable_map = sp.csr_matrix((self.nnz, 0))
        every = np.arange(n)  # (node, a): row 3 node + a, column 3 node + 2
        z_row, z_col = index[3 * every[:, None] + np.arange(3)].ravel(), index[3 * every + 2]
        self.z_take = np.flatnonzero((z_row >= 0) & (z_col.repeat(3) >= 0))
        node = self.z_take // 3
        self.z_slots = (self.indptr[z_row[self.z_take]] + offset[diagonal_entry[node]]
                        + rank[3 * node + 2])

    def _strand_map(self, m: int, entry: np.ndarray, sym: np.ndarray, n_entries: int
                    ) -> sp.csr_matrix:
        """CSR data <- the strands' upper triangles (m, 6): each CSR entry (node entry
        `entry`, place `sym` in its block) sums the strand blocks of its node entry, the
        strands from the last to the first (a stable sort of the blocks taken in reverse),
        each block's value at the entry's place in it."""
        blocks = self._slot_parts[0][0][2].ravel()  # node entry of each strand's 4 blocks
        order = blocks.size - 1 - np.argsort(blocks[::-1], kind="stable")
        strand = _index(6 * (order // 4), 6 * m)  # each sorted block's first upper value
        sign = _PAIR_SIGN[order % 4]
        count = np.bincount(blocks, minlength=n_entries)
        per = count[entry]  # strand blocks at each CSR entry
        indptr = np.concatenate([[0], np.cumsum(per)])
        at = np.arange(indptr[-1]) + np.repeat(
            (np.cumsum(count) - count)[entry] - indptr[:-1], per)
        return sp.csr_matrix((sign[at], strand[at] + np.repeat(sym, per),
                              _index(indptr, int(indptr[-1]))), shape=(self.nnz, 6 * m))

    @cached_property
    def _slot_maps(self) -> tuple[np.ndarray, ...]:
        """The CSR start of every dof's row (n x 3), whether it is free, and every node
        entry's column offset per free dof and whether that column is free (entries x 3)."""
        _, index, fmask, offset, rank, ecol = self._slot_parts
        row_at = np.where(fmask, self.indptr[:-1][np.maximum(index, 0)].reshape(fmask.shape), 0)
        return row_at, fmask, offset[:, None] + rank.reshape(fmask.shape)[ecol], fmask[ecol]

    def _group_slots(self, group: tuple[str, np.ndarray, np.ndarray]
                     ) -> tuple[np.ndarray, np.ndarray]:
        """(kept, CSR positions of the kept) slots of one slot group."""
        kind, p, e = group
        return _positions(kind, p, e, *self._slot_maps)

    @cached_property
    def _slots(self) -> tuple[np.ndarray, np.ndarray]:
        parts = [self._group_slots(g) for g in self._slot_parts[0]]
        return np.concatenate([k for k, _ in parts]), np.concatenate([s for _, s in parts])

    @property
    def keep(self) -> np.ndarray:
        """Which slots have a free row and column (slot order)."""
        return self._slots[0]

    @property
    def slot(self) -> np.ndarray:
        """The CSR position of every kept slot."""
        return self._slots[1]

    def member_blocks(self, weights: np.ndarray) -> np.ndarray:
        """CSR data of the slot values `pair_values(w I3)` of the strands, then every
        cable's segments (weights w in that order; zeros in every other slot), summed as
        `scatter` sums them: the diagonal of a node block gets its node entry's values in
        slot order, the rest exact zeros."""
        entry, n_entries = self._members
        sums = np.bincount(entry.ravel(), (weights[:, None] * _PAIR_SIGN).ravel(), n_entries)
        data = np.zeros(self.nnz)
        on = self._block_diagonal
        data[on] = sums[self.entry[on]]
        return data

    def nbytes(self) -> int:
        """Bytes of the arrays and sparse operators this pattern holds (those built so far)."""
        return _nbytes(list(vars(self).values()))

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
        sym = np.take(data, self.upper)  # 0.5 (a + b), in place: the same numbers
        sym += np.take(data, self.upper_transpose)
        sym *= 0.5
        return sp.csc_matrix((sym, *self._upper_index), shape=(self.size, self.size))

    def symmetric_upper_csr(self, data: np.ndarray) -> sp.csr_matrix:
        """The same upper triangle in CSR (what MKL PARDISO reads for a symmetric matrix)."""
        rows, mirror, index = self._upper_csr
        sym = 0.5 * (data[rows] + data[mirror])
        return sp.csr_matrix((sym, *index), shape=(self.size, self.size))


def _nbytes(value: object) -> int:
    """Bytes of the arrays and sparse matrices in `value` (nested in tuples and lists)."""
    if isinstance(value, np.ndarray):
        return value.nbytes
    if sp.issparse(value):
        return sum(getattr(value, k).nbytes for k in ("data", "indices", "indptr"))
    if isinstance(value, tuple | list):
        return sum(_nbytes(v) for v in value)
    return 0


def _index(a: np.ndarray, bound: int | None = None) -> np.ndarray:
    """`a` as scipy's index type for it: int32 when its values (below `bound` when given)
    fit, else int64 (`a` itself when it has that type)."""
    top = bound if bound is not None else 0 if a.size == 0 else int(a.max())
    small = top < _INT32_MAX
    return a.astype(np.int32 if small else np.int64, copy=False)


# the shared patterns by topology, each with a dict its users keep derived objects in
# (`shared_extras`), dropped with it
_shared: OrderedDict[bytes, tuple[Pattern, dict, int]] = OrderedDict()  # + its nbytes()
_shared_lock = threading.Lock()


def shared_pattern(n_nodes: int, free: np.ndarray, bar_i: np.ndarray, bar_j: np.ndarray,
                   cable_nodes: list[np.ndarray]) -> Pattern:
    """The Pattern of this topology (node count, free dofs, strand node pairs, cables' node
    sequences), built once per process and shared by every later net of the same topology:
    a Pattern depends on nothing else and is only read once built (the parts it builds
    on demand follow from it alone: any thread gets the same arrays). A band's variants, a
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
