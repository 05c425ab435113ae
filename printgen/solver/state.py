"""The fast path's view of a net: built once per net (nondimensional strands and cables, the
fixed tangent pattern, the damping matrix), evaluated in one strand pass per trial state.

`evaluate` returns everything a Newton step needs at a displacement field: out-of-balance
force, force scale, strain energy, and the per-strand quantities from which `tangent_values`
assembles the tangent without a second pass.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse import csgraph

from .assemble import Bars, bar_energy, nondimensional, strand_laws
from .linsolve import (
    PARDISO_MIN_DOFS,
    Pardiso,
    cholmod_available,
    cholmod_solve,
    ldl_available,
    pardiso_available,
)
from .loads import total_forces
from .model import Net
from .pattern import SYM_PAIRS, pair_values, shared_extras, shared_pattern

_SYM_A, _SYM_B = (np.array(x) for x in zip(*SYM_PAIRS, strict=True))
_SYM_DIAGONAL = np.flatnonzero(_SYM_A == _SYM_B)


class NetSystem:
    """A net in nondimensional form (x / L, F / S) with its fixed tangent pattern."""

    def __init__(self, net: Net) -> None:
        s = nondimensional(net)
        self.net, self.x0, self.n = net, s.x0, len(s.x0)
        self.L, self.S, self.bars, self.cables = s.L, s.S, s.bars, s.cables
        self.cable_set = CableSet(self.cables)
        self.free = s.free
        self.pattern = shared_pattern(self.n, self.free, self.bars.i, self.bars.j,
                                      [c.nodes for c in self.cables])
        self.damping = self._damping()
        self.incidence = _incidence(self.n, self.bars, self.pattern)
        self.loads: list = []
        self._dofs: dict = {}  # `loads.total_forces`'s cache of the loads' dofs
        # each strand's slope just above zero strain: its stiffness once a slack strand pulls
        self.first_slope = np.array([law.slopes[0] for law in self.bars.laws])[
            self.bars.law_index] if len(self.bars.laws) else np.zeros(0)

    def _damping(self) -> np.ndarray:
        """CSR data of D = (graph Laplacian, weights 1 / rest length) x I3, scaled to a mean
        diagonal of 1: the stiffness of a net under unit force density. Damping a step with
        mu D instead of mu I moves a node without stiffness with its neighbours (a membrane
        shape), not alone along its own out-of-balance force."""
        data = self.pattern.member_blocks(np.concatenate(
            [1.0 / self.bars.rest, *(1.0 / c.l0 for c in self.cables)]))
        mean = float(data[self.pattern.diagonal].mean()) if self.pattern.size else 1.0
        data /= mean or 1.0
        return data

    def membrane_shape(self, b: np.ndarray) -> np.ndarray | None:
        """D^-1 b on the free dofs, solved per direction on the node graph (D is the graph
        Laplacian times I3, so the three directions decouple and each system is a third of
        the size); None when a direction's Laplacian is singular (a part of the net reaches
        no anchor)."""
        n, fixed = self.n, self.net.fixed_dofs
        edges = [(self.bars.i, self.bars.j, 1.0 / self.bars.rest)]
        edges += [(c.nodes[:-1], c.nodes[1:], 1.0 / c.l0) for c in self.cables]
        i, j, w = (np.concatenate(x) for x in zip(*edges, strict=True))
        full = np.zeros(3 * n)
        full[self.free] = b
        rhs, out = full.reshape(n, 3), np.zeros((n, 3))
        masks: dict[bytes, list[int]] = {fixed[:, k].tobytes(): [] for k in range(3)}
        for k in range(3):
            masks[fixed[:, k].tobytes()].append(k)
        extras = shared_extras(self.pattern)  # the topology's: kept for its next net
        for dirs in masks.values():  # one factorization per distinct set of free nodes
            nodes = np.flatnonzero(~fixed[:, dirs[0]])
            if not nodes.size:
                continue
            at = np.ix_(nodes, np.asarray(dirs))
            spare = None if extras is None else extras.setdefault(("laplacian", *dirs), {})
            x = _laplacian_solve(n, nodes, (i, j, w), rhs[at], spare)
            if x is None:
                return None
            out[at] = x
        v = out.ravel()[self.free]
        return v if np.all(np.isfinite(v)) else None

    def external(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Nondimensional loads and their z-derivative at nondimensional displacements u."""
        f, dz = total_forces(self.loads, self.x0 + u * self.L, self._dofs)
        return f / self.S, dz * self.L / self.S


def _incidence(n: int, bars: Bars, pattern) -> sp.csr_matrix:
    """The node-by-strand incidence (+1 at a strand's j, -1 at its i): the topology's alone,
    so kept with its shared pattern (`pattern.shared_extras`) for the next net of it and
    only read (61 x 21 nodes: ~0.2 ms a solve for the COO -> CSR conversion)."""
    extras = shared_extras(pattern)
    if extras is not None and "incidence" in extras:
        return extras["incidence"]
    m = len(bars.rest)
    out = sp.csr_matrix((np.repeat([1.0, -1.0], m), (np.concatenate([bars.j, bars.i]),
                         np.tile(np.arange(m), 2))), shape=(n, m))
    return out if extras is None else extras.setdefault("incidence", out)


LAPLACIAN_CHOLMOD_MIN_NODES = 10_000  # from here on CHOLMOD's supernodal Cholesky of the
# membrane start's Laplacian beats qdldl's LDL^T, which fills in column by column (1 thread,
# CPU, simple-pinned: a tie at 4.6k nodes, 19k 0.017 against 0.022 s, 76k 0.09 against
# 0.17 s: benchmarks/measurements.md#state-laplacian-cholmod-min-nodes)


def _laplacian_solve(n: int, nodes: np.ndarray, edges: tuple, rhs: np.ndarray,
                     spare: dict | None = None) -> np.ndarray | None:
    """X with L X = rhs, L the weighted graph Laplacian (edges: i, j, weight) of the n nodes
    restricted to `nodes` (the others held); None when L is singular (some nodes reach no
    held one). From PARDISO_MIN_DOFS unknowns (3 per node) by PARDISO's Cholesky when
    installed, else from LAPLACIAN_CHOLMOD_MIN_NODES nodes by CHOLMOD's when installed, else
    by qdldl's LDL^T of L's upper triangle when installed (half of SuperLU's time on the 61
    x 21 net), else SuperLU.

    spare: a dict kept with the net's topology (`pattern.shared_extras`), which L's
    anchoring and qdldl's object (its ordering) depend on alone: the next net of that
    topology reuses them (61 x 21 nodes: 0.8 -> 0.1 ms)."""
    i, j, w = edges
    spare = {} if spare is None else spare
    if "anchored" not in spare:
        spare["anchored"] = anchored(n, nodes, i, j)
    if not spare["anchored"]:
        return None
    index = np.full(n, -1)
    index[nodes] = np.arange(len(nodes))
    a, b = index[i], index[j]
    inner = (a >= 0) & (b >= 0)
    lo, hi = np.minimum(a[inner], b[inner]), np.maximum(a[inner], b[inner])
    diag = (np.bincount(i, w, n) + np.bincount(j, w, n))[nodes]
    k = np.arange(len(nodes))
    upper = sp.coo_matrix((np.concatenate([diag, -w[inner]]), (np.concatenate([k, lo]),
                           np.concatenate([k, hi]))), shape=(len(nodes),) * 2)
    if 3 * len(nodes) >= PARDISO_MIN_DOFS and pardiso_available():
        x = _pardiso_solve(upper.tocsr(), rhs)
        if x is not None:
            return x
    upper = upper.tocsc()
    if len(nodes) >= LAPLACIAN_CHOLMOD_MIN_NODES and cholmod_available():
        upper.sum_duplicates()  # sorted rows, as cvxopt's matrix takes them
        x = cholmod_solve(upper, rhs)
        if x is not None:
            return x
    try:
        with np.errstate(all="ignore"):
            if ldl_available():
                import qdldl

                ldl = spare.pop("qdldl", None)  # taken: one net at a time
                if ldl is None:
                    ldl = qdldl.Solver(upper, upper=True)
                else:
                    ldl.update(upper, upper=True)
                x = np.column_stack([ldl.solve(np.ascontiguousarray(c)) for c in rhs.T])
                spare["qdldl"] = ldl
                return x
            full = (upper + sp.triu(upper, 1, format="csc").T).tocsc()
            return spla.splu(full).solve(rhs)
    except (RuntimeError, ValueError):  # singular: some nodes reach no anchor through D
        return None


def _pardiso_solve(upper: sp.csr_matrix, rhs: np.ndarray) -> np.ndarray | None:
    """X with L X = rhs by MKL PARDISO's Cholesky of L's upper triangle (CSR), None when it
    fails. On large nets it beats qdldl's LDL^T (1 thread, CPU: 19k free nodes 0.038 against
    0.054 s, 76k 0.13 against 0.29 s; a tie at 4.6k)."""
    solver = Pardiso()
    try:
        solver.factor(upper)
        return np.column_stack([solver.solve(np.ascontiguousarray(c)) for c in rhs.T])
    except solver.error:
        return None
    finally:
        solver.free()


def anchored(n: int, nodes: np.ndarray, i: np.ndarray, j: np.ndarray) -> bool:
    """True when every node of `nodes` reaches a held node (one not in `nodes`) along the
    edges (i, j): then their Laplacian is positive definite. Checked on the graph, since a
    factorization of a singular Laplacian need not meet an exact zero pivot (a loose panel
    of 667 nodes beside the 61 x 21 net: LDL^T returned a finite shape of 3e11)."""
    held = np.ones(n, bool)
    held[nodes] = False
    graph = sp.csr_matrix((np.ones(len(i)), (i, j)), shape=(n, n))  # what csgraph reads
    count, label = csgraph.connected_components(graph, directed=False)
    reached = np.zeros(count, bool)  # the parts that hold a held node
    reached[label[held]] = True
    return bool(reached[label[nodes]].all())


class CableSet:
    """All sliding cables at once: their segments concatenated (a, b node pairs, D0, |D0|,
    owning cable), so a state costs a few array operations however many cables there are."""

    def __init__(self, cables: list) -> None:
        self.count = len(cables)
        self.rest = np.array([c.rest for c in cables], dtype=float)
        distinct = list(dict.fromkeys(c.law for c in cables))  # laws are frozen, hashable
        self.groups = [(law, np.array([k for k, c in enumerate(cables) if c.law == law]))
                       for law in distinct]
        self.offsets = np.cumsum([0, *[len(c.l0) for c in cables]])
        if cables:
            self.a = np.concatenate([c.nodes[:-1] for c in cables])
            self.b = np.concatenate([c.nodes[1:] for c in cables])
            self.d0 = np.concatenate([c.d0 for c in cables])
            self.l0 = np.concatenate([c.l0 for c in cables])
            self.owner = np.repeat(np.arange(self.count), np.diff(self.offsets))
            self.l0_sum = np.bincount(self.owner, self.l0, self.count)

    def strains(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(cable strains (c,), unit vectors (s, 3), lengths (s,)) of every segment."""
        du = u[self.b] - u[self.a]
        d = self.d0 + du
        length = np.sqrt(np.einsum("ij,ij->i", d, d))
        stretch = (2 * np.einsum("ij,ij->i", self.d0, du) + np.einsum("ij,ij->i", du, du)) / (
            length + self.l0)
        eps = (np.bincount(self.owner, stretch, self.count) + self.l0_sum - self.rest) / self.rest
        return eps, d / length[:, None], length

    def laws_at(self, eps: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(tension, tangent, energy per rest length) of each cable at its strain (one law
        evaluation per distinct law)."""
        t, kt, e = np.zeros(self.count), np.zeros(self.count), np.zeros(self.count)
        for law, sel in self.groups:
            t[sel], kt[sel], e[sel] = law.evaluate(eps[sel])
        return t, kt, e


@dataclass
class State:
    """A trial displacement field u (n, 3) and what follows from it (nondimensional)."""

    u: np.ndarray
    r: np.ndarray  # out-of-balance force on the free dofs
    r_norm: float  # max |r|
    f_norm: float  # force scale: max(|F_ext|, strand and cable tensions)
    energy: float  # strain energy
    f: np.ndarray  # external forces (n, 3)
    dz: np.ndarray  # their z-derivative (n, 3)
    bar: tuple  # (strain, force, tangent, d, l) of the strands
    cab: tuple  # (tensions, tangents, unit vectors, lengths) of the cables and segments

    def potential(self, f_frozen: np.ndarray) -> float:
        """Total potential with the loads frozen at another state's values."""
        return self.energy - float((f_frozen * self.u).sum())


def _strains(b: Bars, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(strain, current vector d, length l) of every strand (np.take: a row gather several
    times quicker than fancy indexing)."""
    du = np.take(u, b.j, axis=0) - np.take(u, b.i, axis=0)
    d = b.d0 + du
    length = np.sqrt(np.einsum("ij,ij->i", d, d))
    d0_du = b.d0[:, 0] * du[:, 0] + b.d0[:, 1] * du[:, 1] + b.d0[:, 2] * du[:, 2]
    dl2 = b.c + 2 * d0_du + np.einsum("ij,ij->i", du, du)
    return dl2 / (b.rest * (length + b.rest)), d, length


def evaluate(ns: NetSystem, u: np.ndarray) -> State:
    """Forces, energy and strand states at u, in one pass over the strands."""
    b = ns.bars
    eps, d, length = _strains(b, u)
    force, tangent, energy = strand_laws(b, eps)
    g = ns.incidence @ ((force / length)[:, None] * d)
    scales = [float(force.max()) if force.size else 0.0]
    cab: tuple = ()
    cs = ns.cable_set
    if cs.count:
        ce, nvec, ls = cs.strains(u)
        t, kt, e = cs.laws_at(ce)
        fseg = np.maximum(t, 0.0)[cs.owner][:, None] * nvec
        for k in range(3):
            g[:, k] += (np.bincount(cs.b, fseg[:, k], ns.n) - np.bincount(cs.a, fseg[:, k], ns.n))
        energy += float((cs.rest * e).sum())
        scales.append(float(t.max()))
        cab = (t, kt, nvec, ls)
    f, dz = ns.external(u)
    r = (g - f).ravel()[ns.free]
    scales.append(float(np.abs(f).max()) if f.size else 0.0)
    return State(u, r, float(np.abs(r).max()) if r.size else 0.0, max(max(scales), 1e-300),
                 energy, f, dz, (eps, force, tangent, d, length), cab)


def ray_potential(ns: NetSystem, u: np.ndarray, w: np.ndarray, f_frozen: np.ndarray
                  ) -> Callable[[float], float]:
    """The total potential (strain energy minus the work of the frozen loads f_frozen) at
    u + t w as a function of t, for scalar searches along one direction:
    each strand's squared length and stretch are quadratics in t whose coefficients are
    computed once, so a value costs a few operations per strand, not a pass over (m, 3)
    arrays (the same numbers to round-off)."""
    b = ns.bars
    base = np.take(u, b.j, axis=0) - np.take(u, b.i, axis=0)
    dw = np.take(w, b.j, axis=0) - np.take(w, b.i, axis=0)
    d = b.d0 + base
    sq0, lin, quad = (np.einsum("ij,ij->i", x, y) for x, y in ((d, d), (d, dw), (dw, dw)))
    dl0 = b.c + 2 * np.einsum("ij,ij->i", b.d0, base) + np.einsum("ij,ij->i", base, base)
    work0, work1 = float((f_frozen * u).sum()), float((f_frozen * w).sum())
    cs = ns.cable_set

    def value(t: float) -> float:
        sq = (2 * t) * lin + (t * t) * quad
        eps = (dl0 + sq) / (b.rest * (np.sqrt(sq0 + sq) + b.rest))
        energy = bar_energy(b, eps)
        if cs.count:
            energy += float((cs.rest * cs.laws_at(cs.strains(u + t * w)[0])[2]).sum())
        return energy - (work0 + t * work1)

    return value


def tangent_values(ns: NetSystem, st: State) -> np.ndarray:
    """CSR data of the tangent K - dF_ext/du at a state (the pattern's slot order)."""
    _, force, tangent, d, length = st.bar
    n = d / length[:, None]
    geo = np.where(force > 0, force / length, 0.0)
    # geo (I - n n^T) + mat n n^T, by the upper triangle of each strand's block
    upper = (tangent / ns.bars.rest - geo)[:, None] * (n[:, _SYM_A] * n[:, _SYM_B])
    upper[:, _SYM_DIAGONAL] += geo[:, None]
    vals = []
    cs = ns.cable_set
    for k, c in enumerate(ns.cables):
        t, kt = st.cab[0][k], st.cab[1][k]
        if t <= 0:
            vals.append(np.zeros(36 * len(c.l0) + (3 * len(c.nodes)) ** 2))
            continue
        seg = slice(cs.offsets[k], cs.offsets[k + 1])
        nvec, ls = st.cab[2][seg], st.cab[3][seg]
        cnn = np.einsum("ki,kj->kij", nvec, nvec)
        vals.append(pair_values((t / ls)[:, None, None] * (np.eye(3)[None] - cnn)).ravel())
        grad = np.zeros((len(c.nodes), 3))
        grad[:-1] -= nvec
        grad[1:] += nvec
        gv = grad.ravel()
        vals.append((kt / c.rest) * np.outer(gv, gv).ravel())
    cables = np.concatenate(vals) if vals else np.zeros(0)
    return ns.pattern.assemble(upper, cables, st.dz)
