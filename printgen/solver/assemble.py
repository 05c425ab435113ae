"""Internal forces and tangent stiffness of strands and sliding cables, vectorised, in the
solver's nondimensional units (lengths / L_ref, forces / S_ref).

Strain is computed stably as eps = (l^2 - L0^2) / (L0 (l + L0)) with
l^2 - L0^2 = (|D0|^2 - L0^2) + 2 D0.du + |du|^2, D0 the initial node-to-node vector and du the
difference of the displacements: no cancellation in l - L0 even when strains are 1e-9 of the
node coordinates (lambda = 100, stiff strands).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from .laws import Law
from .model import Net


@dataclass(frozen=True)
class Bars:
    """Two-node tension-only strands: i, j (m,), D0 (m, 3), rest L0 (m,), c = |D0|^2 - L0^2."""

    i: np.ndarray
    j: np.ndarray
    d0: np.ndarray
    rest: np.ndarray
    c: np.ndarray
    law_index: np.ndarray
    laws: list[Law]

    @cached_property
    def groups(self) -> tuple[tuple[Law, slice | np.ndarray], ...]:
        """Each law that has strands, with them: a slice when they are consecutive (the usual
        case: a view, no copy), else their indices; in the order of `laws`."""
        out = []
        for k, law in enumerate(self.laws):
            idx = np.flatnonzero(self.law_index == k)
            if idx.size:
                whole = idx[-1] - idx[0] + 1 == idx.size
                out.append((law, slice(int(idx[0]), int(idx[-1]) + 1) if whole else idx))
        return tuple(out)


@dataclass(frozen=True)
class Cable:
    """Sliding cable: nodes (k,), segment vectors D0 (k-1, 3), |D0|, rest length of the whole."""

    nodes: np.ndarray
    d0: np.ndarray
    l0: np.ndarray
    rest: float
    law: Law


def make_bars(x0: np.ndarray, elements: np.ndarray, rest: np.ndarray, law_index: np.ndarray,
              laws: list[Law]) -> Bars:
    i, j = np.ascontiguousarray(elements[:, 0]), np.ascontiguousarray(elements[:, 1])
    d0 = x0[j] - x0[i]
    return Bars(i, j, d0, rest, np.einsum("ij,ij->i", d0, d0) - rest**2, law_index, laws)


def make_cable(x0: np.ndarray, nodes: np.ndarray, rest: float, law: Law) -> Cable:
    d0 = np.diff(x0[nodes], axis=0)
    return Cable(nodes, d0, np.linalg.norm(d0, axis=1), rest, law)


def strand_laws(b: Bars, eps: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """(force, tangent, strain energy) of the strands at strains `eps`: one law evaluation
    per law, on its strands."""
    force, tangent = np.zeros_like(eps), np.zeros_like(eps)
    energy = 0.0
    for law, sel in b.groups:
        force[sel], tangent[sel], e = law.evaluate(eps[sel])
        energy += float((b.rest[sel] * e).sum())
    return force, tangent, energy


def bar_state(b: Bars, u: np.ndarray):
    """(strain, force, tangent, current vector d, length l) of every strand."""
    du = u[b.j] - u[b.i]
    d = b.d0 + du
    length = np.linalg.norm(d, axis=1)
    dl2 = b.c + 2 * np.einsum("ij,ij->i", b.d0, du) + np.einsum("ij,ij->i", du, du)
    eps = dl2 / (b.rest * (length + b.rest))
    force, tangent, _ = strand_laws(b, eps)
    return eps, force, tangent, d, length


def cable_state(c: Cable, u: np.ndarray):
    """(strain, tension, tangent, unit vectors (k-1, 3), segment lengths) of a sliding cable."""
    du = np.diff(u[c.nodes], axis=0)
    d = c.d0 + du
    length = np.linalg.norm(d, axis=1)
    stretch = ((2 * np.einsum("ij,ij->i", c.d0, du) + np.einsum("ij,ij->i", du, du))
               / (length + c.l0))
    eps = (stretch.sum() + (c.l0.sum() - c.rest)) / c.rest
    t, kt = c.law.force_and_tangent(np.array([eps]))
    return float(eps), float(t[0]), float(kt[0]), d / length[:, None], length


def _block_entries(rows, cols, blocks):
    """COO entries of (k, 3, 3) blocks at node pairs (rows, cols)."""
    r = (3 * rows[:, None, None] + np.arange(3)[None, :, None]).repeat(3, axis=2)
    c = (3 * cols[:, None, None] + np.arange(3)[None, None, :]).repeat(3, axis=1)
    return r.ravel(), c.ravel(), blocks.ravel()


def internal(bars: Bars, cables: list[Cable], u: np.ndarray, n_nodes: int, *,
             with_tangent: bool = True):
    """Resisting forces g (n, 3) and, when asked, the tangent K (3n x 3n, CSR)."""
    g = np.zeros((n_nodes, 3))
    rows: list[np.ndarray] = []
    cols: list[np.ndarray] = []
    vals: list[np.ndarray] = []
    _, force, tangent, d, length = bar_state(bars, u)
    taut = force > 0
    n = d / length[:, None]
    fn = force[:, None] * n
    np.add.at(g, bars.i, -fn)
    np.add.at(g, bars.j, fn)
    if with_tangent and taut.any():
        nn = np.einsum("ki,kj->kij", n[taut], n[taut])
        geo = (force[taut] / length[taut])[:, None, None]
        mat = (tangent[taut] / bars.rest[taut])[:, None, None]
        k = geo * (np.eye(3)[None] - nn) + mat * nn
        i, j = bars.i[taut], bars.j[taut]
        for a, b, s in ((i, i, 1), (j, j, 1), (i, j, -1), (j, i, -1)):
            r, c, v = _block_entries(a, b, s * k)
            rows.append(r)
            cols.append(c)
            vals.append(v)
    for cab in cables:
        _, t, kt, nvec, ls = cable_state(cab, u)
        if t <= 0:
            continue
        grad = np.zeros((len(cab.nodes), 3))
        grad[:-1] -= nvec
        grad[1:] += nvec
        np.add.at(g, cab.nodes, t * grad)
        if not with_tangent:
            continue
        nn = np.einsum("ki,kj->kij", nvec, nvec)
        k = (t / ls)[:, None, None] * (np.eye(3)[None] - nn)
        a, b = cab.nodes[:-1], cab.nodes[1:]
        for p, q, s in ((a, a, 1), (b, b, 1), (a, b, -1), (b, a, -1)):
            r, c, v = _block_entries(p, q, s * k)
            rows.append(r)
            cols.append(c)
            vals.append(v)
        # all nodes of a cable share its tension: rank-one coupling kt/L0 grad grad^T
        dof = (3 * cab.nodes[:, None] + np.arange(3)).ravel()
        gv = grad.ravel()
        rows.append(np.repeat(dof, len(dof)))
        cols.append(np.tile(dof, len(dof)))
        vals.append((kt / cab.rest) * np.outer(gv, gv).ravel())
    if not with_tangent:
        return g, None
    size = 3 * n_nodes
    if rows:
        K = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(size, size))
    else:
        K = sp.csr_matrix((size, size))
    return g, K


def bar_energy(bars: Bars, eps: np.ndarray) -> float:
    """Strain energy of the strands at strains `eps` (nondimensional)."""
    total = 0.0
    for law, sel in bars.groups:
        total += float((bars.rest[sel] * law.energy(eps[sel])).sum())
    return total


def strain_energy(bars: Bars, cables: list[Cable], u: np.ndarray) -> float:
    """Total strain energy of strands and cables (nondimensional)."""
    total = bar_energy(bars, bar_state(bars, u)[0])
    for c in cables:
        total += c.rest * float(c.law.energy(np.array([cable_state(c, u)[0]]))[0])
    return total


@dataclass(frozen=True)
class Scaled:
    """A net in nondimensional form: lengths / L (the net's extent), forces / S (the steepest
    law slope); its strands and cables in those units, and the free degrees of freedom."""

    x0: np.ndarray  # (n, 3) node positions, m
    L: float
    S: float
    bars: Bars
    cables: list[Cable]
    free: np.ndarray  # (3 n,) bool


def nondimensional(net: Net) -> Scaled:
    """The nondimensional form shared by the reference and the fast path."""
    x0 = np.asarray(net.nodes, dtype=float)
    L = float(np.linalg.norm(x0.max(axis=0) - x0.min(axis=0))) or 1.0
    slopes = [s for law in net.laws for s in law.slopes]
    slopes += [s for c in net.cables for s in c.law.slopes]
    S = float(max(slopes))
    bars = make_bars(x0 / L, np.asarray(net.elements, dtype=int), net.rest_lengths() / L,
                     net.law_index, [law.scaled(1 / S) for law in net.laws])
    cables = [make_cable(x0 / L, np.asarray(c.nodes, dtype=int), net.cable_rest_length(c) / L,
                         c.law.scaled(1 / S)) for c in net.cables]
    return Scaled(x0, L, S, bars, cables, ~net.fixed_dofs.ravel())
