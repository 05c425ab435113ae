"""Solver against closed forms: V cable, discrete cable under uniform load, slack strand,
sliding cable over a pulley-like node."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from printgen.solver import Net, PointLoads, SlidingCable, SolverError, linear, piecewise, solve

EXACT_FORM = 1e-9  # relative error allowed where the closed form is exact (issue 4)
TIGHT = 1e-13  # solver force tolerance for the analytic cases: far below EXACT_FORM
ROOT_XTOL = 1e-15  # scalar root of the closed forms, solved to round-off


def _fixed_ends(n: int) -> np.ndarray:
    f = np.zeros(n, dtype=bool)
    f[[0, -1]] = True
    return f


@pytest.mark.parametrize("ea, load", [(1e5, 100.0), (2e7, 1.0), (10.0, 3.0)])
def test_v_cable_under_point_load(ea, load):
    """Two segments of length L, zero pretension: 2 T sin(a) = P, T = EA (1/cos(a) - 1)."""
    span = 1.0
    nodes = np.array([[0, 0, 0], [span, 0, 0], [2 * span, 0, 0]], float)
    net = Net(nodes, _fixed_ends(3), np.array([[0, 1], [1, 2]]), [linear(ea)])
    r = solve(net, [PointLoads(np.array([1]), np.array([[0, load, 0]]))], tol=TIGHT)
    a = brentq(lambda a: 2 * ea * (1 / np.cos(a) - 1) * np.sin(a) - load, 1e-12, 1.5,
               xtol=ROOT_XTOL)
    assert r.converged
    assert r.displacements[1, 1] == pytest.approx(span * np.tan(a), rel=EXACT_FORM)
    assert r.tensions[0] == pytest.approx(ea * (1 / np.cos(a) - 1), rel=EXACT_FORM)


def test_discrete_cable_under_uniform_load():
    """N equal segments, equal transverse loads P at the interior nodes. The horizontal force
    H is constant; segment k carries V_k = P ((N-1)/2 - k) and T_k = hypot(H, V_k); the
    stretched lengths L0 (1 + T_k / EA) must close the span: one scalar equation for H."""
    n_seg, span, ea, p = 12, 6.0, 5e4, 20.0
    l0 = span / n_seg
    x = np.linspace(0, span, n_seg + 1)
    nodes = np.column_stack([x, np.zeros_like(x), np.zeros_like(x)])
    el = np.column_stack([np.arange(n_seg), np.arange(1, n_seg + 1)])
    net = Net(nodes, _fixed_ends(n_seg + 1), el, [linear(ea)])
    inner = np.arange(1, n_seg)
    r = solve(net, [PointLoads(inner, np.tile([0.0, p, 0.0], (len(inner), 1)))], tol=TIGHT)
    v = p * ((n_seg - 1) / 2 - np.arange(n_seg))

    def gap(h):
        t = np.hypot(h, v)
        return (l0 * (1 + t / ea) * h / t).sum() - span

    h = brentq(gap, 1e-6, 1e9, xtol=ROOT_XTOL, rtol=4 * np.finfo(float).eps)
    t = np.hypot(h, v)
    seg = l0 * (1 + t / ea)
    y = np.concatenate([[0.0], np.cumsum(seg * v / t)])
    xs = np.concatenate([[0.0], np.cumsum(seg * h / t)])
    assert r.converged
    np.testing.assert_allclose(r.positions[:, 1], y, rtol=EXACT_FORM, atol=EXACT_FORM * y.max())
    np.testing.assert_allclose(r.positions[:, 0], xs, rtol=EXACT_FORM, atol=EXACT_FORM * span)
    np.testing.assert_allclose(r.tensions, t, rtol=EXACT_FORM)


def test_slack_strand_carries_zero_force():
    """A node between two anchors pushed along the line: the far strand goes slack (exactly
    zero force), the near one carries the whole load: x = 1 + P / EA."""
    ea, p = 1e4, 25.0
    nodes = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0]], float)
    net = Net(nodes, _fixed_ends(3), np.array([[0, 1], [1, 2]]), [linear(ea)])
    r = solve(net, [PointLoads(np.array([1]), np.array([[p, 0, 0]]))], tol=TIGHT)
    assert r.converged
    assert r.tensions[1] == 0.0 and r.slack[1] and not r.slack[0]
    assert r.positions[1, 0] == pytest.approx(1 + p / ea, rel=EXACT_FORM)
    assert r.tensions[0] == pytest.approx(p, rel=EXACT_FORM)


def test_initially_slack_strand_stays_at_zero_force_until_taut():
    """Rest length 1 % longer than the span: under a load that takes up only part of the
    slack the strand carries nothing, and the net converges to a state with zero tension."""
    nodes = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0]], float)
    net = Net(nodes, _fixed_ends(3), np.array([[0, 1], [1, 2]]), [linear(1e4)], slack=0.01)
    r = solve(net, [PointLoads(np.array([1]), np.array([[0, 1.0, 0]]))], tol=TIGHT)
    assert r.converged and np.all(r.tensions > 0)
    # the slack is taken up first: sag at least sqrt(1.01^2 - 1)
    assert r.displacements[1, 1] > np.sqrt(1.01**2 - 1)


def test_sliding_cable_equal_tension_over_a_pulley():
    """A cable from (0,0) over a free node to (2,0), the node starting off-centre at x = 0.5
    and pulled sideways: it slides to the middle (equal tension both sides), and
    2 T y / (L / 2) = P with L = L0 (1 + T / EA)."""
    ea, p = 1e4, 50.0
    nodes = np.array([[0, 0, 0], [0.5, 0, 0], [2, 0, 0]], float)
    cable = SlidingCable(np.array([0, 1, 2]), linear(ea))
    net = Net(nodes, _fixed_ends(3), np.zeros((0, 2), int), [linear(ea)], cables=[cable])
    r = solve(net, [PointLoads(np.array([1]), np.array([[0, p, 0]]))], tol=TIGHT)

    def gap(t):
        half = 2.0 * (1 + t / ea) / 2
        y = np.sqrt(half**2 - 1)
        return 2 * t * y / half - p

    t = brentq(gap, 1e-9, 1e9, xtol=ROOT_XTOL)
    half = 1 + t / ea
    assert r.converged
    assert r.positions[1, 0] == pytest.approx(1.0, rel=EXACT_FORM)
    assert r.positions[1, 1] == pytest.approx(np.sqrt(half**2 - 1), rel=EXACT_FORM)
    assert r.cable_tensions[0] == pytest.approx(t, rel=EXACT_FORM)


def test_piecewise_law_matches_its_closed_form():
    """Softening law (TPE-like): the V cable's tension follows the law at its strain."""
    law = piecewise([0.4], [30.0, 6.0])
    nodes = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0]], float)
    net = Net(nodes, _fixed_ends(3), np.array([[0, 1], [1, 2]]), [law])
    r = solve(net, [PointLoads(np.array([1]), np.array([[0, 20.0, 0]]))], tol=TIGHT)
    eps = r.strains[0]
    assert r.converged and eps > 0.4  # beyond the knee
    assert r.tensions[0] == pytest.approx(30 * 0.4 + 6 * (eps - 0.4), rel=EXACT_FORM)


@pytest.mark.parametrize("method", ["fast", "reference"])
def test_unconverged_is_never_silent(method):
    """One step is too few for either path (the fast path's membrane start and chord steps
    reach this V cable in two)."""
    nodes = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0]], float)
    net = Net(nodes, _fixed_ends(3), np.array([[0, 1], [1, 2]]), [linear(1e5)])
    loads = [PointLoads(np.array([1]), np.array([[0, 100.0, 0]]))]
    r = solve(net, loads, max_iter=1, method=method)
    assert not r.converged and "no convergence in 1 iterations" in r.reason
    with pytest.raises(SolverError, match="no convergence"):
        solve(net, loads, max_iter=1, strict=True, method=method)


def test_bad_laws_are_rejected():
    for knees, slopes in (((), (-1.0,)), ((0.2,), (1.0,)), ((0.3, 0.2), (1.0, 2.0, 3.0))):
        with pytest.raises(ValueError):
            piecewise(knees, slopes)


@pytest.mark.parametrize("bad", [{"slack": -0.1}, {"slack": 0.01, "pretension": 5.0}])
def test_bad_models_are_rejected(bad):
    nodes = np.array([[0, 0, 0], [1, 0, 0]], float)
    kw = {"laws": [linear(1.0)]}
    kw.update(bad)
    with pytest.raises(ValueError):
        Net(nodes, np.array([True, False]), np.array([[0, 1]]), **kw)


def test_drag_ramps_in_as_the_water_covers_a_node():
    """The drag of a node grows linearly from its height to `ramp` above it, and its
    z-derivative is the slope of that ramp (what Newton needs)."""
    from printgen.solver import Drag

    full = 0.5 * 1000.0 * 2.0**2 * 0.3 * 0.01  # 0.5 rho v^2 l d
    x = np.array([[0.0, 0.0, 1.0]])
    for level, share in ((0.9, 0.0), (1.0, 0.0), (1.05, 0.5), (1.1, 1.0), (3.0, 1.0)):
        _, f, dfdz = Drag(np.array([0]), 0.3, 0.01, 2.0, level, ramp=0.1).evaluate(x)
        assert f[0, 1] == pytest.approx(full * share, rel=EXACT_FORM)
        slope = -full / 0.1 if 0 < share < 1 else 0.0
        assert dfdz[0, 1] == pytest.approx(slope, rel=EXACT_FORM)


def test_a_path_reports_unreachable_levels_and_can_go_on():
    """With too few iterations allowed every level fails: the path stops at the first one,
    or with skip_failed keeps going, each failure converged=False with its reason."""
    from printgen.solver import solve_path

    nodes = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0]], float)
    net = Net(nodes, _fixed_ends(3), np.array([[0, 1], [1, 2]]), [linear(1e5)])

    def loads_at(level):
        return [PointLoads(np.array([1]), np.array([[0, 100.0 * level, 0]]))]

    stopped = solve_path(net, loads_at, [0.5, 1.0], max_iter=1, max_cuts=1)
    assert len(stopped) == 1 and not stopped[0].converged
    assert "load level 0.5" in stopped[0].reason
    went_on = solve_path(net, loads_at, [0.5, 1.0], max_iter=1, max_cuts=1, skip_failed=True)
    assert [r.converged for r in went_on] == [False, False]
    with pytest.raises(SolverError, match="load level 0.5"):
        solve_path(net, loads_at, [0.5, 1.0], max_iter=1, max_cuts=1, strict=True)
    ok = solve_path(net, loads_at, [0.5, 1.0])
    assert all(r.converged for r in ok) and ok[1].tensions[0] > ok[0].tensions[0]
