"""Solver on the reference scenes (barrier-physics.md, section 7): similitude invariance,
the steel-at-every-scale trend, the (F / EA)^(1/3) law, refinement, tolerance, hard cases."""

from __future__ import annotations

import numpy as np
import pytest

from printgen.solver import solve
from printgen.solver.scenes import SIMPLE, simple_scene

SIMILAR = 1e-9  # issue 4: same normalised deformation at every lambda with E / lambda
TIGHT = 1e-12  # solver tolerance for the invariance checks
SLOPE = 0.02  # the one-third law is the small-strain limit: 2 % on the fitted exponent
LAMBDAS = (1, 10, 30, 50, 100)


def normalised(scale, modulus, *, tol=TIGHT, level=1.0, **kw):
    sc = simple_scene(scale=scale, modulus=modulus, pinned_top=False, drag=False, **kw)
    r = solve(sc.net, sc.loads_at(level), tol=tol)
    assert r.converged, r.reason
    return (r.displacements[sc.centre, 1] / sc.width,
            -r.displacements[sc.top_centre, 2] / sc.height, r)


@pytest.fixture(scope="module")
def scaled_series():
    return {lam: normalised(lam, SIMPLE["modulus"] / lam)[:2] for lam in LAMBDAS}


def test_scaled_modulus_gives_the_same_normalised_deformation(scaled_series):
    d1, l1 = scaled_series[1]
    assert d1 > 0.01 and l1 > 0.01  # a real deformation, not a trivial zero
    for lam in LAMBDAS[1:]:
        d, low = scaled_series[lam]
        assert d == pytest.approx(d1, rel=SIMILAR), lam
        assert low == pytest.approx(l1, rel=SIMILAR), lam


@pytest.mark.slow
def test_steel_at_every_scale_deflects_less_as_lambda_grows(scaled_series):
    steel = [normalised(lam, SIMPLE["modulus"])[0] for lam in (10, 30, 100)]
    assert scaled_series[1][0] > steel[0] > steel[1] > steel[2]


@pytest.mark.slow
def test_zero_pretension_net_follows_the_one_third_law():
    """Deflection / width ~ (F / EA)^(1/3) at small strain: vary EA at fixed load."""
    moduli = np.array([1e12, 1e13, 1e14])  # very stiff: strains 1e-5..1e-6
    d = np.array([normalised(1, e)[0] for e in moduli])
    slope = np.polyfit(np.log(1 / moduli), np.log(d), 1)[0]
    assert slope == pytest.approx(1 / 3, rel=SLOPE)


@pytest.mark.slow
def test_mesh_refinement_converges():
    """simple-pinned at 61 x 21, 121 x 41, 181 x 61 nodes, same loads per unit area."""
    d = []
    for refine in (1, 2, 3):
        sc = simple_scene(refine=refine)
        r = solve(sc.net, sc.loads_at(1.0))
        assert r.converged, r.reason
        d.append(r.displacements[sc.centre, 1])
    assert abs(d[2] - d[1]) < abs(d[1] - d[0])
    assert abs(d[2] - d[1]) / d[2] < 0.01  # 1 %: the coarse mesh is already close


def test_tightening_the_tolerance_converges():
    """Tolerances two orders apart or more: the fast path's last Newton steps converge
    quadratically, so 1e-7 and 1e-10 can end on the same iterate."""
    sc = simple_scene(pinned_top=False, drag=False)
    ref = solve(sc.net, sc.loads_at(1.0), tol=1e-13).displacements
    errs = [np.abs(solve(sc.net, sc.loads_at(1.0), tol=t).displacements - ref).max()
            for t in (1e-3, 1e-5, 1e-10)]
    assert errs[0] > errs[1] > errs[2] or errs[2] == 0.0
    assert errs[2] < 1e-9 * np.abs(ref).max()


@pytest.mark.slow
@pytest.mark.parametrize("lam", [1, 100])
@pytest.mark.parametrize("slack", [0.002, 0.02])
def test_slack_nets_converge_and_stay_similar(lam, slack):
    """Every strand starts slack (the net is a mechanism); lambda = 1 and 100 agree."""
    d, _low, r = normalised(lam, SIMPLE["modulus"] / lam, slack=slack, tol=1e-10)
    d1, _low1, _ = normalised(1, SIMPLE["modulus"], slack=slack, tol=1e-10)
    assert r.converged and d > 0
    assert d == pytest.approx(d1, rel=1e-6)  # looser tolerance (1e-10) than TIGHT


def test_very_soft_strands_at_forty_percent_strain():
    """simple-pinned with 0.5 GPa strands: about 40 % strain at overflow (110 %)."""
    sc = simple_scene(modulus=5e8, drag=False)
    r = solve(sc.net, sc.loads_at(1.1))
    assert r.converged, r.reason
    assert 0.2 < r.strains.max() < 0.8


def test_overflow_at_lambda_100_with_drag():
    sc = simple_scene(scale=100, modulus=SIMPLE["modulus"] / 100, drag=True)
    r = solve(sc.net, sc.loads_at(1.1))
    assert r.converged, r.reason
    assert r.residual <= 1e-10 * r.load_norm
