"""Public entry points: `solve` one load case, `solve_path` a sequence of load levels.

method="fast" (default) runs `solver.fast`; method="reference" runs the plain regularised
Newton method of `solver.newton` (COO assembly and SuperLU at every step), kept as the
reference the fast path is tested against. Both return converged=False with the reason (or
raise SolverError when `strict`) instead of an unconverged answer.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence

import numpy as np

from . import newton
from .assemble import cable_state
from .fast import Stepper, best_start, iterate, membrane_start
from .linsolve import cholmod_available, choose_backend
from .model import Net
from .newton import MAX_CUTS, MAX_ITER, TOL_FORCE
from .result import Result, SolverError
from .state import NetSystem, State, evaluate

METHODS = ("fast", "reference")
PATH_CHOLMOD_MIN_DOFS = 1_000  # along a load path, CHOLMOD from here on where `choose_backend`
# takes qdldl (its CHOLMOD_MIN_DOFS weighs single solves, which pay the analysis each): numeric
# factorizations of the design search's model nets, 1 thread, CPU, qdldl / CHOLMOD: 1.0k
# unknowns 0.64 / 0.42 ms, 1.5k 0.99 / 0.62 ms, 2.3k 2.39 / 1.13 ms; the first, with the
# analysis, 1.50 / 1.61 ms and 4.64 / 3.61 ms (smaller nets not measured: they keep qdldl)


class FastSolver:
    """One net's fast solves: its pattern, ordering and factorization reused across loads."""

    def __init__(self, net: Net, backend: str | None = None) -> None:
        self.ns = NetSystem(net)
        self.stepper = Stepper(self.ns, backend)

    def solve(self, loads: Sequence, starts: list[np.ndarray], tol: float, max_iter: int,
              level: float | None = None) -> Result:
        """Equilibrium under `loads` from the best of `starts` (m; none or all zero: rest)."""
        t0, f0 = time.perf_counter(), self.stepper.factorizations
        ns = self.ns
        ns.loads = list(loads)
        if starts and any(np.any(u) for u in starts):
            st = best_start(ns, [np.asarray(u, dtype=float) / ns.L for u in starts])
        else:
            st = membrane_start(ns, evaluate(ns, np.zeros_like(ns.x0)), self.stepper)
        st, iters, ok, reason = iterate(ns, st, tol, max_iter, self.stepper)
        return _result(ns, st, iters, ok, reason, time.perf_counter() - t0, level,
                       self.stepper.factorizations - f0, self.stepper.backend)


def _result(ns: NetSystem, st: State, iters: int, ok: bool, reason: str, seconds: float,
            level: float | None, factorizations: int, backend: str) -> Result:
    eps, force = st.bar[0], st.bar[1]  # the strand pass `evaluate` made at st.u
    cab = [cable_state(c, st.u) for c in ns.cables]
    disp = st.u * ns.L
    return Result(ns.x0 + disp, disp, eps, force * ns.S, force <= 0,
                  np.array([c[0] for c in cab]), np.array([c[1] * ns.S for c in cab]),
                  st.r_norm * ns.S, st.f_norm * ns.S, iters, ok, reason, seconds, level,
                  factorizations, backend)


def path_backend(size: int) -> str:
    """The linear backend of a load path of a net of `size` unknowns: `choose_backend`'s,
    except CHOLMOD instead of qdldl from PATH_CHOLMOD_MIN_DOFS unknowns when it is installed
    (a path factorizes its net tens of times, so CHOLMOD's analysis pays back sooner)."""
    backend = choose_backend(size)
    if backend == "ldl" and size >= PATH_CHOLMOD_MIN_DOFS and cholmod_available():
        return "cholmod"
    return backend


def _check(method: str) -> None:
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")


def solve(net: Net, loads: Sequence, *, u0: np.ndarray | None = None, tol: float = TOL_FORCE,
          max_iter: int = MAX_ITER, strict: bool = False, level: float | None = None,
          method: str = "fast") -> Result:
    """Equilibrium of `net` under `loads` from displacements `u0` (m; default: rest).

    Returns a Result with converged=False and the reason when it fails; raises SolverError
    instead when `strict`.
    """
    _check(method)
    if method == "reference":
        return newton.solve(net, loads, u0=u0, tol=tol, max_iter=max_iter, strict=strict,
                            level=level)
    res = FastSolver(net).solve(loads, [] if u0 is None else [u0], tol, max_iter, level)
    if strict and not res.converged:
        raise SolverError(res.reason)
    return res


def _starts(history: list[tuple[float, np.ndarray]], target: float) -> list[np.ndarray]:
    """Warm starts for a level: the last converged state, and its extrapolation from the two
    last converged levels (a secant predictor)."""
    if not history:
        return []
    (l2, u2) = history[-1]
    if len(history) < 2 or history[-2][0] == l2:
        return [u2]
    l1, u1 = history[-2]
    return [u2, u2 + (u2 - u1) * ((target - l2) / (l2 - l1))]


def _shifted(paths: Callable[[float], list[np.ndarray | None]],
             history: list[tuple[float, np.ndarray]], target: float, fixed: np.ndarray
             ) -> list[np.ndarray]:
    """Starts from other nets' converged paths (`paths(level)`: each net's displacements
    there, None where it has none; one entry per net, in one order at every level): a net's
    change from this path's last converged level to `target`, added to this path's state
    there (its path shifted onto this one: nets that differ by a border or a strand section
    differ little in how a load step moves them); its own state where it has none at that
    level, or before this path has converged anywhere."""
    shape = fixed.shape
    now = paths(target)
    then = paths(history[-1][0]) if history else [None] * len(now)
    out = []
    for g, h in zip(now, then, strict=True):
        if g is None or np.shape(g) != shape:  # another net's: not a start here
            continue
        if h is None or np.shape(h) != shape:
            out.append(np.where(fixed, 0.0, g))
        else:
            out.append(history[-1][1] + np.where(fixed, 0.0, g - h))
    return out


def solve_path(net: Net, loads_at: Callable[[float], Sequence],
               levels: Sequence[float] | np.ndarray, *,
               tol: float = TOL_FORCE, max_iter: int = MAX_ITER, strict: bool = False,
               max_cuts: int = MAX_CUTS, skip_failed: bool = False,
               method: str = "fast",
               guesses: Callable[[float], list[np.ndarray]] | None = None,
               paths: Callable[[float], list[np.ndarray | None]] | None = None,
               backend: str | None = None) -> list[Result]:
    """Solve at each level in order, warm-started; a failing level is reached by sub-steps:
    each failure halves the sub-step from the last converged state (at most `max_cuts`
    halvings per level), each success goes on by the same sub-step towards the level.

    `guesses(level)`: more starts (displacements, m) for a level, e.g. a similar net's
    converged state there; the fast method starts from the lowest potential of these and the
    path's own starts, so a poor guess costs one evaluation, never the answer (a guess of
    another shape is ignored; a guess is taken at rest at this net's supports, since Newton
    moves the free degrees of freedom only and would keep a guess's displacement there: the
    state of a net held elsewhere, e.g. another mounting, starts this one where it is free).
    `paths(level)`: other nets' converged paths of this net's shape (`_shifted`: each net's
    states, one entry per net and None where it has none), more starts for the fast method:
    each net's load step shifted onto this path. `backend`: the fast method's linear backend
    (None: `choose_backend`'s for the net's size; `path_backend` gives a path's).
    Returns one Result per level. A level that cannot be reached stops the path (strict
    raises SolverError instead); with `skip_failed` its unconverged Result (converged=False,
    with the reason) is kept and the next level starts from the last converged state.
    """
    _check(method)
    fast = FastSolver(net, backend) if method == "fast" else None
    fixed = net.fixed_dofs
    out: list[Result] = []
    history: list[tuple[float, np.ndarray]] = []
    done = 0.0
    for level in levels:
        res, cuts, step, target = None, 0, level - done, level
        while True:
            if fast is not None:
                extra = [] if guesses is None else [  # another net's: not a start here
                    np.where(fixed, 0.0, g) for g in guesses(target)
                    if np.shape(g) == fast.ns.x0.shape]
                if paths is not None:
                    extra += _shifted(paths, history, target, fixed)
                res = fast.solve(loads_at(target), _starts(history, target) + extra, tol,
                                 max_iter, target)
            else:
                res = newton.solve(net, loads_at(target), u0=history[-1][1] if history else None,
                                   tol=tol, max_iter=max_iter, level=target)
            if res.converged:
                history.append((target, res.displacements))
                done = target
                if target == level:
                    break
                # on from the sub-step reached, by sub-steps of the size that converged
                target = level if abs(level - done) <= abs(step) else done + step
                continue
            if cuts >= max_cuts:
                break
            cuts += 1
            step *= 0.5  # halved from the last converged state, not from the level's start
            target = done + step
        if not res.converged:
            msg = f"load level {level:g}: {res.reason} (after {cuts} step cuts)"
            if strict:
                raise SolverError(msg)
            out.append(Result(**{**res.__dict__, "reason": msg, "level": level}))
            if not skip_failed:
                return out
            continue
        out.append(res)
    return out
