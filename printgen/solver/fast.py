"""The fast path: the regularised Newton method of `solver.newton` (same convergence test,
same energy line search and step cap), computed with less work per step and fewer steps:

- one strand pass per trial state (`solver.state`), the tangent scattered into a pattern
  fixed per net (`solver.pattern`), factorized by a sparse LDL^T whose ordering is reused
  (`solver.linsolve`: MKL PARDISO for large nets, qdldl's LDL^T, SuperLU without either);
- steps damped by mu D (D: the net's stiffness under unit force density) instead of mu I;
- a membrane start from rest: the shape of the net under unit force density, scaled to the
  lowest potential along it, instead of the flat net;
- chord steps on large nets: after a full Newton step the same factorization is tried once
  more, and kept while it at least halves the out-of-balance force (modified Newton);
- along load paths, a start extrapolated from the last two converged levels when its
  potential is lower than the last level's state;
- a non-monotone Armijo test (the last NONMONOTONE states), so full Newton steps survive
  while strands settle slack or taut; mu grows tenfold when no damped step descends (the
  follower load can make the damped tangent indefinite);
- inexact Newton: linear solves to a residual of min(FORCING, |R| / force scale);
- an active set on the tension-only law: the slack strands a step stretches past their
  rest length get their stiffness (and the pull their strain offset implies) in its model,
  and the step is solved again until that set stops changing (a primal-dual active set on
  the piecewise quadratic model, at most PDAS_PASSES re-solves, each by GMRES preconditioned
  by the step's own factorization: one factorization per Newton step); the set the last
  pass predicts is the next step's first guess. Without it a free-top net's dry strands,
  slack and held only by the hold of unloaded nodes, let a step run through their rest
  length unresisted: the line search cut it to a few per cent for hundreds of iterations
  (simple barrier's model at 1:40, first loaded level: 311 iterations, now 39);
- mixed-integration-point Newton (Magisano, Leonetti & Garcea 2017, Comput. Methods Appl.
  Mech. Engrg. 313): the geometric stiffness of each step uses the strand tensions the last
  step's own model predicted, not the tensions recomputed at the new state. A step that
  swings a node across a nearly slack strand stretches it to second order (|d_perp|^2 / 2l),
  which the linear model leaves out; recomputed, that spurious tension stiffens the next
  step's transverse response and Newton creeps. The residual, the line search and the
  convergence test use the true tensions, so the answer is unchanged (simple barrier 1:40,
  model / prototype sweeps: worst level 39 / 44 -> 28 / 38 iterations; band's slack-1 %
  variant 979 -> 780 in all).

The tangent is not symmetric (hydrostatic follower term): every step solves the true
system; the symmetric part only serves as a factorization to precondition it
(`solver.linsolve`) and, failing all else, as a descent direction of the energy.
The answer is the same (R = 0 to the same tolerance): only the path to it differs.
"""

from __future__ import annotations

import contextlib
import dataclasses
import threading
from collections.abc import Callable

import numpy as np

from .linsolve import Cholmod, Factorization, Ldl, choose_backend, lazy_norm, refine
from .newton import (
    ARMIJO,
    MAX_BACKTRACK,
    MAX_STEP,
    MU_FACTOR,
    MU_MIN,
    POTENTIAL_ROUND_OFF,
    ROUND_OFF,
)
from .pattern import shared_extras
from .state import NetSystem, State, evaluate, ray_potential, tangent_values

FORCING = 0.1  # inexact Newton: linear solves to min(FORCING, |R| / force scale), relative
MU_GROWTH = 10.0  # mu grows by this factor when no damped step descends
MU_RETRIES = 6  # ... at most this many times in one iteration
NONMONOTONE = 5  # Armijo against the highest potential of the last 5 Newton states
CHORD_RATE = 0.5  # a chord step is kept when it at least halves the out-of-balance force
CHORD_MIN_DOFS = 10_000  # below, a factorization costs less than the trial state a chord step
# needs, so no chord steps (benchmarks/measurements.md#fast-chord-and-repass)
START_SPAN = (-6.0, 0.0)  # log10 of the membrane start's largest displacement / net extent
START_GRID = 13  # potentials sampled over START_SPAN before the scalar minimisation
START_XTOL = 0.01  # log10 resolution of the membrane start's scale
# backends whose re-passes are GMRES on the first pass's factorization: a triangular solve of
# qdldl's LDL^T costs ~1/10 of its factorization; PARDISO refactorizes cheaper than the 5-10
# preconditioned iterations, and so does the "ldl" backend once it has switched to PARDISO
# along a load path (`_repass_by_gmres`; benchmarks/measurements.md#fast-chord-and-repass)
REPASS_BY_GMRES = ("ldl",)
PDAS_PASSES = 1  # active-set re-solves per Newton step at most, each by GMRES on the first
# pass's factorization: more passes save few Newton iterations for much more CPU
# (benchmarks/measurements.md#fast-chord-and-repass)


# a finished net's linear-solver handle, per backend, kept with its tangent pattern while
# that is shared (`pattern.shared_extras`: one pattern per topology) for the next net of the
# pattern: qdldl's AMD ordering and CHOLMOD's symbolic analysis depend on the pattern alone,
# so that net's factorizations are numeric only (61 x 21 nodes, qdldl: the first 4.0 -> 1.8
# ms), with the same factors
_SPARE_LOCK = threading.Lock()


def _spare_handle(ns: NetSystem, backend: str) -> Ldl | Cholmod | None:
    """A spare handle of the net's pattern and backend, or None."""
    extras = shared_extras(ns.pattern)
    if extras is None:
        return None
    with _SPARE_LOCK:
        handle = extras.setdefault("spare_handles", {}).pop(backend, None)
    if isinstance(handle, Ldl):
        handle.count = 0  # this net's own factorizations decide a switch to PARDISO
    return handle


def _reusable(handle: object, pattern: object) -> bool:
    """Whether a handle is as a new net's would be after its analysis: a qdldl one (not
    switched to PARDISO), a CHOLMOD one of this pattern (not turned to LDL^T)."""
    if isinstance(handle, Ldl):
        return handle.qdldl is not None and handle.pardiso is None
    if isinstance(handle, Cholmod):
        return handle.ldl is None and handle.source is pattern
    return False


class Stepper:
    """Factorizations of one net, reusing the backend's ordering; counts what it does."""

    def __init__(self, ns: NetSystem, backend: str | None = None) -> None:
        self.ns = ns
        self.backend = backend or choose_backend(ns.pattern.size)
        self.handle = _spare_handle(ns, self.backend)
        self.factorizations = 0
        self.active: np.ndarray | None = None  # slack strands the last step's model stretched
        self.predicted: np.ndarray | None = None  # strand tensions the last step's model reached

    def factor(self, data: np.ndarray) -> Factorization:
        fact = Factorization(self.ns.pattern, data, self.backend, self.handle)
        self.handle = fact.handle  # None after a failed factorization: a fresh one next time
        self.factorizations += 1
        return fact

    def matrix(self, st: State, boost: float = 1.0) -> np.ndarray:
        """CSR data of J + mu D at `st`, mu = MU_FACTOR |R| x boost (floored)."""
        data = tangent_values(self.ns, st)  # a fresh array: the damping is added in place
        diag = float(np.abs(data[self.ns.pattern.diagonal]).max()) if data.size else 0.0
        mu = max(MU_FACTOR * float(np.linalg.norm(st.r)), MU_MIN * max(diag, 1e-300))
        data += boost * mu * self.ns.damping
        return data

    def newton(self, st: State, boost: float = 1.0) -> Factorization:
        return self.factor(self.matrix(st, boost))

    def __del__(self) -> None:
        """Leave the handle to the next net of the pattern (`_spare_handle`) when `_reusable`."""
        with contextlib.suppress(Exception):  # at interpreter exit, modules may be gone
            pattern = self.ns.pattern
            extras = shared_extras(pattern)
            if extras is not None and _reusable(self.handle, pattern):
                with _SPARE_LOCK:
                    extras.setdefault("spare_handles", {})[self.backend] = self.handle


def iterate(ns: NetSystem, st: State, tol: float, max_iter: int, stepper: Stepper
            ) -> tuple[State, int, bool, str]:
    """(state, iterations, converged, reason) from state `st` (chord steps count too).

    At the round-off level (max |R| <= ROUND_OFF but above tol x the force scale) one more
    Newton step is still taken while it lowers max |R|: the answer then does not depend on
    how close to round-off the path happened to land."""
    it, chord = 0, None
    recent: list[float] = []
    stepper.predicted = None  # the first step's geometric stiffness: the tensions at `st`
    while True:
        if st.r_norm <= tol * st.f_norm:
            return st, it, True, "converged"
        if it >= max_iter:
            return st, it, False, (f"no convergence in {max_iter} iterations: max out-of-balance "
                                   f"{st.r_norm * ns.S:.3g} N, {st.r_norm / st.f_norm:.2g} of "
                                   "the load")
        it += 1
        if chord is not None and st.r_norm > ROUND_OFF and ns.pattern.size >= CHORD_MIN_DOFS:
            trial = _chord_step(ns, st, chord)
            if trial is not None:
                st = trial
                continue
        recent = [*recent[-(NONMONOTONE - 1):], st.potential(st.f)]
        fact, found = _newton_step(ns, st, stepper, max(recent))
        if st.r_norm <= ROUND_OFF and (found is None or found[0].r_norm >= st.r_norm):
            return st, it, True, "converged (round-off)"
        if found is None:
            return st, it, False, (f"line search failed: no step lowers the energy or the "
                                   f"out-of-balance force ({st.r_norm * ns.S:.3g} N, "
                                   f"{st.r_norm / st.f_norm:.2g} of the load)")
        st, alpha = found
        chord = fact if alpha == 1.0 else None


def _newton_step(ns: NetSystem, st: State, stepper: Stepper, reference: float):
    """(factorization, (state, step length) or None): the damped Newton step, then the step on
    its symmetric part; when neither lowers the potential (the follower load can make the
    damped tangent indefinite) mu grows tenfold, at most MU_RETRIES times."""
    forcing = min(FORCING, st.r_norm / st.f_norm)
    for attempt in range(MU_RETRIES + 1):
        fact, first, rhs, strained = _active_set_step(ns, st, stepper, MU_GROWTH**attempt,
                                                      forcing)
        for which in range(2):  # the symmetric step solved only when the first fails
            step = first if which == 0 else fact.symmetric_solve(rhs)
            found = None if step is None else _line_search(ns, st, step, reference)
            if found is not None:
                assert stepper.active is not None  # _active_set_step has just set it
                stepper.predicted = _predicted_tensions(
                    ns, st, stepper.active, step, found[1], stepper.predicted,
                    strained if which == 0 else None)
                return fact, found
    return fact, None


def _active_set_step(ns: NetSystem, st: State, stepper: Stepper, boost: float, forcing: float):
    """(factorization, step, right-hand side, the step's strand strain increments B step):
    the damped Newton step on the piecewise quadratic model in which a slack strand pulls
    once the step's linearised strain eps + B s turns positive; the set of such strands is
    iterated to a fixed point (primal-dual active set), at most PDAS_PASSES times, from the
    last step's set."""
    eps, force, tangent, d, length = st.bar
    b = ns.bars
    slack = force <= 0
    nvec = d / length[:, None]
    active = np.zeros_like(slack)
    if stepper.active is not None:
        active = slack & stepper.active
    fact: Factorization | Updated | None = None
    step = rhs = strained = None
    new = active
    geometric = force if stepper.predicted is None else stepper.predicted
    for _ in range(PDAS_PASSES + 1):
        tan = np.where(active, ns.first_slope, tangent)
        at = dataclasses.replace(st, bar=(eps, geometric, tan, d, length))
        trial: Factorization | Updated
        if fact is None or not _repass_by_gmres(stepper):
            trial = stepper.newton(at, boost)
        else:
            base = fact.base if isinstance(fact, Updated) else fact
            trial = Updated(ns.pattern.csr(stepper.matrix(at, boost)), base, stepper)
        off = ns.incidence @ (np.where(active, ns.first_slope * eps, 0.0)[:, None] * nvec)
        new_rhs = -st.r - off.ravel()[ns.free]
        new_step = trial.solve(new_rhs, forcing)
        if new_step is None:
            if fact is None:
                fact, rhs = trial, new_rhs
            break
        fact, step, rhs = trial, new_step, new_rhs
        du = _moved(ns, np.zeros_like(st.u), step)
        strained = np.einsum("ij,ij->i", nvec, _span(b, du)) / b.rest
        new = slack & (eps + strained > 0)
        if np.array_equal(new, active):
            break
        active = new
    stepper.active = new  # the set the last step predicts: the next step's first guess
    return fact, step, rhs, strained


def _repass_by_gmres(stepper: Stepper) -> bool:
    """Whether an active-set re-pass solves by GMRES on the first pass's factorization (a
    backend of REPASS_BY_GMRES whose factorizations are not PARDISO's) or factorizes afresh."""
    return (stepper.backend in REPASS_BY_GMRES
            and getattr(stepper.handle, "pardiso", None) is None)


def _predicted_tensions(ns: NetSystem, st: State, pulls: np.ndarray, step: np.ndarray,
                        alpha: float, last: np.ndarray | None, de: np.ndarray | None = None
                        ) -> np.ndarray:
    """The strand tensions the step's own model predicts at its end (mixed integration
    point Newton, Magisano, Leonetti & Garcea 2017): the last prediction moved by alpha
    towards the linearised law's tension at the full step, floored at zero (tension only);
    `pulls`: the slack strands the step stretches (`Stepper.active`); `de`: the step's
    strand strain increments when known (`_active_set_step` computed them)."""
    eps, force, tangent, d, length = st.bar
    if de is None:
        b = ns.bars
        du = _moved(ns, np.zeros_like(st.u), step)
        de = np.einsum("ij,ij->i", d / length[:, None], _span(b, du)) / b.rest
    model = np.where(force > 0, force + tangent * de, np.where(pulls, ns.first_slope * (eps + de),
                                                               0.0))
    base = force if last is None else last
    return np.maximum(base + alpha * (model - base), 0.0)


class Updated:
    """The system of an active-set re-pass, solved by GMRES preconditioned by the pass
    before's factorization (the matrices differ by the few strands whose state changed), and
    factorized afresh only when that misses the target."""

    def __init__(self, A, base: Factorization, stepper: Stepper) -> None:
        self.A, self.base, self.stepper = A, base, stepper

    def solve(self, b: np.ndarray, forcing: float = 0.0) -> np.ndarray | None:
        base = self.base
        precondition = base.direct if base.direct is not None else (
            base.lu.solve if base.lu is not None else None)
        if precondition is not None:
            with np.errstate(all="ignore"):
                x = refine(self.A, precondition, b, np.zeros_like(b), forcing,
                           lazy_norm(self.A, base.pattern.row_starts))
            if x is not None:
                return x
        self.stepper.factorizations += 1  # counted like the stepper's own
        fresh = Factorization(base.pattern, self.A.data, base.backend, None)
        return fresh.solve(b, forcing)

    def symmetric_solve(self, b: np.ndarray) -> np.ndarray | None:
        return self.base.symmetric_solve(b)


def _chord_step(ns: NetSystem, st: State, fact: Factorization) -> State | None:
    step = fact.solve(-st.r, min(FORCING, st.r_norm / st.f_norm))
    if step is None or float(np.abs(step).max()) > MAX_STEP:
        return None
    trial = evaluate(ns, _moved(ns, st.u, step))
    pi0, pi = st.potential(st.f), trial.potential(st.f)
    if trial.r_norm <= CHORD_RATE * st.r_norm and pi <= pi0 + POTENTIAL_ROUND_OFF * abs(pi0):
        return trial
    return None


def _span(b, du: np.ndarray) -> np.ndarray:
    """du[j] - du[i] of every strand (np.take: a row gather several times quicker than
    fancy indexing, the same values)."""
    return np.take(du, b.j, axis=0) - np.take(du, b.i, axis=0)


def _moved(ns: NetSystem, u: np.ndarray, step: np.ndarray) -> np.ndarray:
    out = u.copy()
    out.ravel()[ns.free] += step
    return out


def _line_search(ns: NetSystem, st: State, step: np.ndarray, reference: float | None = None):
    """(state, step length alpha) from backtracking as in `solver.newton._line_search`, but
    non-monotone: the Armijo test is against `reference`, the highest potential of the last
    NONMONOTONE states (Grippo et al. 1986), so a full Newton step may raise the potential a
    little while strands settle slack or taut; the window still forces a decrease. The first
    trial is evaluated whole (most steps end there); the shorter ones take their potentials
    from `ray_potential` (loads frozen at `st`, as before: the same numbers to round-off, a
    few operations per strand each) and only the accepted one is evaluated."""
    alpha = min(1.0, MAX_STEP / max(float(np.abs(step).max()), 1e-300))
    slope = float(st.r @ step)
    if slope >= 0:
        return None
    pi0 = st.potential(st.f)
    highest = max(pi0, reference if reference is not None else pi0)
    along = None
    for _ in range(MAX_BACKTRACK):
        trial = None
        if along is None:
            trial = evaluate(ns, _moved(ns, st.u, alpha * step))
            pi = trial.potential(st.f)
        else:
            pi = along(alpha)
        if pi <= highest + ARMIJO * alpha * slope:
            return trial or evaluate(ns, _moved(ns, st.u, alpha * step)), alpha
        if abs(alpha * slope) < POTENTIAL_ROUND_OFF * max(abs(pi0), abs(pi), 1e-300):
            trial = trial or evaluate(ns, _moved(ns, st.u, alpha * step))
            if trial.r_norm < st.r_norm:
                return trial, alpha
        if along is None:
            along = ray_potential(ns, st.u, _moved(ns, np.zeros_like(st.u), step), st.f)
        alpha *= 0.5
    return None


def membrane_start(ns: NetSystem, st: State, stepper: Stepper) -> State:
    """From rest: solve D v = F (the net under unit force density), then scale v to the
    lowest potential along it. Returns `st` unchanged when that does not lower it."""
    if not st.r.size or st.r_norm == 0.0:
        return st
    v = ns.membrane_shape(-st.r)
    if v is None:  # a part of the net hangs on nothing in D: factorize D whole
        v = stepper.factor(ns.damping.copy()).solve(-st.r)
    if v is None or not np.any(v):
        return st
    v = v / float(np.abs(v).max())
    along = ray_potential(ns, st.u, _moved(ns, np.zeros_like(st.u), v), st.f)

    def pot(log_s: float) -> float:
        return along(10.0**log_s)

    grid = np.linspace(*START_SPAN, START_GRID)
    values = [pot(x) for x in grid]
    k = int(np.argmin(values))
    log_s, best = golden(pot, grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)], START_XTOL)
    if best > values[k]:
        log_s, best = float(grid[k]), values[k]
    if best >= st.potential(st.f):
        return st
    return evaluate(ns, _moved(ns, st.u, 10.0**log_s * v))


def golden(fn: Callable[[float], float], lo: float, hi: float, xtol: float) -> tuple[float, float]:
    """(x, fn(x)) at the minimum of a unimodal fn on [lo, hi], to xtol (golden section)."""
    ratio = (np.sqrt(5.0) - 1.0) / 2.0
    a, b = lo + (1 - ratio) * (hi - lo), lo + ratio * (hi - lo)
    fa, fb = fn(a), fn(b)
    while hi - lo > xtol:
        if fa <= fb:
            hi, b, fb = b, a, fa
            a = lo + (1 - ratio) * (hi - lo)
            fa = fn(a)
        else:
            lo, a, fa = a, b, fb
            b = lo + ratio * (hi - lo)
            fb = fn(b)
    return (a, fa) if fa <= fb else (b, fb)


def best_start(ns: NetSystem, candidates: list[np.ndarray]) -> State:
    """The candidate start of lowest potential (loads frozen at the first candidate)."""
    states = [evaluate(ns, u) for u in candidates]
    f = states[0].f
    return min(states, key=lambda s: s.potential(f))
