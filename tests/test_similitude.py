"""Similitude targets: lambda = 1 identity, exact exponents, Pi groups, flow checks."""

from __future__ import annotations

import math

import numpy as np
import pytest
from proto_files import REALISTIC, SIMPLE, write_variant

from printgen.errors import InputError
from printgen.inputs.prototype import load_prototype
from printgen.scaling.similitude import check_scale, scale_targets

EXACT = 1e-12  # relative: exponents are applied in closed form, only round-off remains


@pytest.fixture(scope="module")
def realistic():
    return load_prototype(REALISTIC)


@pytest.mark.parametrize("path", [REALISTIC, SIMPLE])
def test_scale_one_returns_the_prototype(path):
    t = scale_targets(load_prototype(path), 1)
    for r in t.rows:
        assert r.model == r.prototype, r.key
    assert t.pi_model == t.pi_prototype


@pytest.mark.parametrize("lam", [1.0, 2.5, 10.0, 40.0, 100.0])
def test_forces_scale_as_lambda_to_minus_three(realistic, lam):
    t = scale_targets(realistic, lam)
    for key in ("hydrostatic_force", "cable_ea"):
        row = next(r for r in t.rows if r.key == key)
        assert row.model == pytest.approx(row.prototype * lam**-3, rel=EXACT)


def test_exponents_of_the_scaling_table(realistic):
    lam = 40.0
    t1, t40 = scale_targets(realistic, 1), scale_targets(realistic, lam)
    expected = {"width": -1, "mesh_x": -1, "strand_d": -1, "velocity": -0.5, "cable_modulus": -1,
                "cable_ea": -3, "kappa_0": -1, "kappa_1": -1, "membrane_0": -2, "strain": 0,
                "cable_area": -2}
    for key, e in expected.items():
        assert t40[key] / t1[key] == pytest.approx(lam**e, rel=EXACT), key


def test_1_40_headline_targets(realistic):
    """The reference's 1:40 targets (Lambert et al. 2023): 330 x 100 mm barrier, cable E*A
    = 100 GPa * pi/4 * (24 mm)^2 / 40^3, kappa 250 -> 6.25 kN/m/m."""
    t = scale_targets(realistic, 40)
    assert t["width"] == pytest.approx(0.33, rel=EXACT)
    assert t["cable_ea"] == pytest.approx(100e9 * math.pi / 4 * 0.024**2 / 40**3, rel=EXACT)
    assert t["kappa_0"] == pytest.approx(6250.0, rel=EXACT)
    assert t["membrane_0"] == pytest.approx(250e3 * 1.33 / 1600, rel=EXACT)


@pytest.mark.parametrize("lam", [1.0, 7.0, 40.0, 100.0])
def test_pi_groups_are_scale_invariant(realistic, lam):
    t = scale_targets(realistic, lam)
    for k, v in t.pi_prototype.items():
        assert t.pi_model[k] == pytest.approx(v, rel=1e-9), k  # round-off of lambda powers


def test_reynolds_uses_the_hydraulic_radius(realistic):
    t = scale_targets(realistic, 40)
    w, h, v = 0.4, 1.0 / 40, 2.2 / math.sqrt(40)
    assert t.flow.reynolds == pytest.approx(v * (w * h / (w + 2 * h)) / 1e-6, rel=EXACT)
    assert t.flow.froude == pytest.approx(2.2 / math.sqrt(9.81), rel=EXACT)
    assert t.flow.warnings == ()


def test_laminar_and_oversized_models_warn(realistic):
    t = scale_targets(realistic, 100)  # the largest scale allowed: Re ~ 2100
    assert any("not turbulent" in w for w in t.flow.warnings)
    t = scale_targets(realistic, 10)  # 1.32 m wide model in a 0.4 m flume
    assert any("exceeds the flume width" in w for w in t.flow.warnings)


def test_discharge_limit_warns(tmp_path):
    p = write_variant(tmp_path, {("flume", "max_discharge_l_per_s"): 1.0})
    t = scale_targets(load_prototype(p), 40)
    assert any("exceeds the flume's 1.00 L/s" in w for w in t.flow.warnings)


@pytest.mark.parametrize("bad", [0.5, 0.0, -3.0, float("nan"), float("inf"), True, "40", 101.0,
                                 1e9])
def test_bad_scale_is_an_input_error(bad):
    with pytest.raises(InputError, match="scale"):
        check_scale(bad)


def test_targets_are_finite_across_scales(realistic):
    for lam in np.geomspace(1, 100, 9):
        t = scale_targets(realistic, lam)
        assert all(math.isfinite(r.model) and r.model > 0 for r in t.rows)
