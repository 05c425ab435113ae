"""Equilibrium of a tension-only net by a regularised (Levenberg-Marquardt) Newton method:
the reference path (method="reference"; `solver.fast` computes the same more cheaply).

Why not plain Newton: a flat net without pretension has no out-of-plane stiffness at the
start (every strand at exactly its rest length: zero tension, zero geometric stiffness), and a
net with initial slack is a mechanism until its strands tighten, so the tangent K is singular
exactly where the solve begins. Each step solves (K - dF_ext/du + mu I) du = -R on the free
degrees of freedom: with mu large this is a short step along the out-of-balance force, with mu
-> 0 it is Newton's step, quadratically convergent. A step is accepted only when it lowers the
out-of-balance force; then mu shrinks tenfold, else it grows fourfold and the step is retried
(a singular factorization counts as a rejected step). The converged state satisfies R = 0 for
the true K: mu only shapes the path, never the answer (a vanishing regularisation).

Units: the solve runs on x / L_ref and F / S_ref (L_ref the net's extent, S_ref its stiffest
strand law), so a net at 1:100 or of 0.02 GPa polymer sees the same numbers as the prototype.
The hydrostatic load depends on the current node height; its derivative enters the tangent.
Load paths (`solver.driver.solve_path`, either method) are solved level by level, each
warm-started from the previous state; a level that fails is approached through halved
sub-steps (automatic step cutting).
"""

from __future__ import annotations

import time
from collections.abc import Sequence

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .assemble import bar_state, cable_state, internal, nondimensional, strain_energy
from .loads import total_forces
from .model import Net
from .result import Result, SolverError

TOL_FORCE = 1e-10  # converged when max |R| <= TOL_FORCE x max(|F_ext|, max strand force)
ROUND_OFF = 1e-15  # nondimensional force (F / S_ref) at the round-off level of the strand laws
MAX_ITER = 400  # accepted + rejected steps together
MU_FACTOR = 1.0  # regulariser mu = MU_FACTOR |R| (nondimensional): vanishes at convergence
MU_MIN = 1e-13  # floor, relative to the largest diagonal of the tangent
ARMIJO = 1e-4  # sufficient decrease of the potential
POTENTIAL_ROUND_OFF = 1e-11  # relative change of the potential below which it is round-off
MAX_BACKTRACK = 40  # step halvings before a line search gives up
MAX_STEP = 0.05  # a step moves no node more than 5 % of the net's extent
MAX_CUTS = 6  # a failed load level is approached by at most 6 halvings


class Problem:
    """A net and loads in nondimensional form, with the free degrees of freedom."""

    def __init__(self, net: Net, loads: Sequence) -> None:
        s = nondimensional(net)
        self.net, self.loads, self.x0, self.n = net, list(loads), s.x0, len(s.x0)
        self.L, self.S, self.bars, self.cables, self.free = s.L, s.S, s.bars, s.cables, s.free

    def external(self, u: np.ndarray):
        """Nondimensional loads and their z-derivative at nondimensional displacements u."""
        f, dz = total_forces(self.loads, self.x0 + u * self.L)
        return f / self.S, dz * self.L / self.S

    def residual(self, u: np.ndarray, with_tangent: bool = True):
        g, K = internal(self.bars, self.cables, u, self.n, with_tangent=with_tangent)
        f, dz = self.external(u)
        r = (g - f).ravel()[self.free]
        if not with_tangent:
            return r, None, f
        if np.any(dz):
            rows = 3 * np.arange(self.n)[:, None] + np.arange(3)
            cols = np.repeat((3 * np.arange(self.n) + 2)[:, None], 3, axis=1)
            K = K - sp.csr_matrix((dz.ravel(), (rows.ravel(), cols.ravel())), shape=K.shape)
        J = K[self.free][:, self.free]
        return r, J.tocsc(), f


def solve(net: Net, loads: Sequence, *, u0: np.ndarray | None = None, tol: float = TOL_FORCE,
          max_iter: int = MAX_ITER, strict: bool = False, level: float | None = None) -> Result:
    """Equilibrium of `net` under `loads` from displacements `u0` (m; default zero).

    Returns a Result with converged=False and the reason when it fails; raises SolverError
    instead when `strict`.
    """
    t0 = time.perf_counter()
    prob = Problem(net, loads)
    u = np.zeros_like(prob.x0) if u0 is None else np.asarray(u0, dtype=float) / prob.L
    u, iters, ok, reason, r_norm, f_norm = _iterate(prob, u, tol, max_iter)
    res = _result(prob, u, r_norm, f_norm, iters, ok, reason, time.perf_counter() - t0, level)
    if strict and not ok:
        raise SolverError(reason)
    return res


def _iterate(prob: Problem, u: np.ndarray, tol: float, max_iter: int):
    """Regularised Newton with an energy line search (see the module docstring)."""
    r, J, f = prob.residual(u)
    it = 0
    while True:
        r_norm = float(np.abs(r).max()) if r.size else 0.0
        f_norm = _force_scale(prob, u, f)
        if r_norm <= tol * f_norm or r_norm <= ROUND_OFF:
            return u, it, True, "converged", r_norm * prob.S, f_norm * prob.S
        if it >= max_iter:
            return (u, it, False, (f"no convergence in {max_iter} iterations: max out-of-balance "
                    f"{r_norm * prob.S:.3g} N, {r_norm / f_norm:.2g} of the load"),
                    r_norm * prob.S, f_norm * prob.S)
        it += 1
        mu = max(MU_FACTOR * float(np.linalg.norm(r)), MU_MIN * _diag_max(J))
        trial = None
        for direction_matrix in (J, _symmetric_part(J)):
            step = _step(direction_matrix, r, mu)
            if step is not None:
                trial = _line_search(prob, u, step, r, r_norm, f)
                if trial is not None:
                    break
        if trial is None:
            return (u, it, False, (f"line search failed: no step lowers the energy or the "
                    f"out-of-balance force ({r_norm * prob.S:.3g} N, {r_norm / f_norm:.2g} of the "
                    "load)"), r_norm * prob.S, f_norm * prob.S)
        u = trial
        r, J, f = prob.residual(u)


def _diag_max(J) -> float:
    return max(float(np.abs(J.diagonal()).max()) if J.nnz else 0.0, 1e-300)


def _symmetric_part(J):
    return ((J + J.T) * 0.5).tocsc()


def _line_search(prob: Problem, u: np.ndarray, step: np.ndarray, r: np.ndarray, r_norm: float,
                 f: np.ndarray) -> np.ndarray | None:
    """Backtrack from the full (capped) step: accept when the out-of-balance force halves or
    the total potential (loads frozen at u) decreases enough (Armijo)."""
    free = prob.free
    alpha = min(1.0, MAX_STEP / max(float(np.abs(step).max()), 1e-300))
    slope = float(r @ step)  # directional derivative of the potential
    if slope >= 0:
        return None
    pi0 = _potential(prob, u, f)
    for _ in range(MAX_BACKTRACK):
        trial = u.copy()
        trial.ravel()[free] += alpha * step
        pi = _potential(prob, trial, f)
        if pi <= pi0 + ARMIJO * alpha * slope:
            return trial
        if abs(alpha * slope) < POTENTIAL_ROUND_OFF * max(abs(pi0), abs(pi), 1e-300):
            # the potential cannot resolve the step any more: judge by the residual
            r_try, _, _ = prob.residual(trial, with_tangent=False)
            if np.abs(r_try).max() < r_norm:
                return trial
        alpha *= 0.5
    return None


def _potential(prob: Problem, u: np.ndarray, f: np.ndarray) -> float:
    return strain_energy(prob.bars, prob.cables, u) - float((f * u).sum())


def _step(J, r: np.ndarray, mu: float) -> np.ndarray | None:
    A = J + mu * sp.identity(J.shape[0], format="csc")
    try:
        with np.errstate(all="ignore"):
            step = spla.spsolve(A, -r)
    except RuntimeError:  # exactly singular factorization
        return None
    return step if np.all(np.isfinite(step)) else None


def _force_scale(prob: Problem, u: np.ndarray, f: np.ndarray) -> float:
    _, force, _, _, _ = bar_state(prob.bars, u)
    scales = [float(np.abs(f).max()) if f.size else 0.0, float(force.max()) if force.size else 0]
    scales += [cable_state(c, u)[1] for c in prob.cables]
    return max(max(scales), 1e-300)


def _result(prob: Problem, u: np.ndarray, r_norm: float, f_norm: float, iters: int, ok: bool,
            reason: str, seconds: float, level: float | None) -> Result:
    eps, force, _, _, _ = bar_state(prob.bars, u)
    cab = [cable_state(c, u) for c in prob.cables]
    disp = u * prob.L
    return Result(prob.x0 + disp, disp, eps, force * prob.S, force <= 0,
                  np.array([c[0] for c in cab]), np.array([c[1] * prob.S for c in cab]),
                  r_norm, f_norm, iters, ok, reason, seconds, level)
