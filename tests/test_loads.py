"""The load cases flow and jam (issue 26): closed forms and limits. Flow's drag at the
level's Froude-held velocity; the jam at porosity 0 is the hydrostatic case, a very porous
jam tends to drag only, its uniform head on a pinned cable gives the parabola, its levels
are the flume's discharge steps; parameters out of range are refused (exit 2)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
from conftest import reference_design_1_40
from proto_files import REALISTIC

from printgen import solver
from printgen.barrier.loads import FLOW, Site, get_load, jam, with_params
from printgen.barrier.loads.drag import strand_drag
from printgen.barrier.loads.jam import DISCHARGES_L_PER_S, ergun_gradient, net_factor, seepage
from printgen.errors import InputError
from printgen.solver.loads import total_forces
from printgen.units import NU_WATER, RHO_WATER, G

EXACT = 1e-12  # closed-form arithmetic, round-off only
ROOT = 1e-9  # relative: a root found to ROOT_TOL (1e-12 m) on depths of 0.01 to 0.1 m
NEAR_DRAG = 2e-3  # porosity 1 - 1e-7: what is left of the jam's head difference, relative
PARABOLA = 0.02  # sag of an elastic cable vs f/L = (3 w L / 64 EA)^(1/3): O((f/L)^2) terms
SHAPE = 0.01  # node deflections / sag vs 4 z (L - z) / L^2 on 41 nodes


def column(n: int = 5, height: float = 1.0, *, pinned_top: bool = False):
    """A vertical column of n nodes 0..height (z), the bottom (and top) one anchored."""
    z = np.linspace(0.0, height, n)
    fixed = np.zeros(n, bool)
    fixed[0] = True
    fixed[-1] = pinned_top
    return SimpleNamespace(nodes=np.column_stack([np.zeros(n), np.zeros(n), z]), fixed=fixed,
                           elements=np.column_stack([np.arange(n - 1), np.arange(1, n)]),
                           area_per_node=0.25, height=height, width=1.0)


def forces(case: str, s, site: Site, r: float) -> np.ndarray:
    return total_forces(get_load(case).loads_for(s, site)(r), s.nodes)[0] @ FLOW


def test_flow_drag_follows_the_froude_held_velocity():
    """v(h) = v_f sqrt(h / h_f): at 3 h_B (every node wet, past the ramp), 0.5 rho v^2 l d on
    each free node above the hydrostatic load; at h = h_f it is the drag case's."""
    s, site = column(), Site(velocity=2.0, strand_diameter=0.01, depth=0.5)
    extra = forces("flow", s, site, 3.0) - forces("hydrostatic", s, site, 3.0)
    v2 = 2.0**2 * 3.0 / 0.5
    want = 0.5 * RHO_WATER * v2 * (1.0 / 5) * 0.01 * (~s.fixed)
    np.testing.assert_allclose(extra, want, rtol=EXACT, atol=EXACT)
    at_hf = Site(velocity=2.0, strand_diameter=0.01, depth=3.0)
    np.testing.assert_allclose(forces("flow", s, at_hf, 3.0), forces("drag", s, at_hf, 3.0),
                               rtol=EXACT, atol=EXACT)
    rec, text = get_load("flow").describe(s, site, np.array([0.0, 0.5, 1.0]))
    assert rec["velocity_m_per_s"] == pytest.approx([0.0, 2.0, 2.0 * math.sqrt(2)], rel=EXACT)
    assert "sqrt(h / 0.5 m)" in text


def test_jam_at_porosity_0_is_the_hydrostatic_case():
    s, site = column(), Site(velocity=1.0, strand_diameter=0.01)
    for r in (0.3, 0.75, 1.0, 1.1):
        np.testing.assert_allclose(forces("jam:porosity=0", s, site, r),
                                   forces("hydrostatic", s, site, r), rtol=EXACT, atol=EXACT)


def test_a_very_porous_jam_tends_to_drag_only():
    """Porosity towards 1 the jam vanishes: its load tends to the drag of the free flow,
    0.5 rho U^2 l d at U = q / h on the wetted nodes (porosity 1: no head lost in the jam);
    a denser jam lies between that and the hydrostatic load."""
    s, site = column(21), Site(velocity=1.0, strand_diameter=0.01)
    r, k = 0.8, net_factor(s) * site.strand_diameter
    assert k == pytest.approx(1 / 21 / 0.25 * 0.01, rel=EXACT)  # l d / A*
    q, hm, _ = seepage(r, k, 1.0, 1.0, 0.1, 1.0)
    drag = strand_drag(s, site.strand_diameter)(hm / s.height, q / hm)
    free_flow = total_forces([drag], s.nodes)[0] @ FLOW
    excess = []
    for porosity in (0.99, 0.9999, 1 - 1e-7):
        f = total_forces(jam.loads(s, site, porosity=porosity, thickness_m=1.0,
                                   log_diameter_m=0.1, tailwater_froude=1.0)(r), s.nodes)[0]
        excess.append(float(np.abs(f @ FLOW - free_flow).sum() / free_flow.sum()))
    assert excess[0] > excess[1] > excess[2] and excess[2] < NEAR_DRAG
    dense = forces("jam:porosity=0.5", s, site, r).sum()
    assert free_flow.sum() < dense < forces("hydrostatic", s, site, r).sum()


def test_ergun_law_and_the_seepage_balance():
    """Ergun's gradient by hand, and the seepage it gives closes the head balance."""
    u, n, d = 0.2, 0.5, 0.01
    dp = 1.5 * d
    hand = (150 * NU_WATER * 0.25 * u / (0.125 * dp**2) + 1.75 * 0.5 * u * u / (0.125 * dp)) / G
    assert ergun_gradient(u, n, d) == pytest.approx(hand, rel=EXACT)
    hu, k, L = 0.1, 0.1, 0.1
    q, hm, hd = seepage(hu, k, n, L, d, 1.0)
    assert hd == pytest.approx((q * q / G) ** (1 / 3), rel=ROOT)
    assert hm - hd == pytest.approx(0.5 * (q / hm) ** 2 * k / G, rel=ROOT)
    assert hu - hm == pytest.approx(L * ergun_gradient(2 * q / (hu + hm), n, d), rel=ROOT)


def test_uniform_jam_head_on_a_pinned_cable_gives_the_parabola():
    """Every node below the water behind the jam: the head difference is uniform, and an
    elastic cable pinned at both ends takes the parabola, sag f/L = (3 w L / 64 EA)^(1/3)."""
    n, length, ea = 41, 1.0, 2e6
    s = column(n, length, pinned_top=True)
    s.area_per_node = length / (n - 1)  # w = load per unit length = pressure x 1 m
    site = Site(velocity=1.0, strand_diameter=1e-4)
    spec = "jam:porosity=0.6,thickness_m=0.5,log_diameter_m=0.3,tailwater_froude=0.5"
    r = 3.0
    _, hm, _ = seepage(r, net_factor(s) * site.strand_diameter, 0.6, 0.5, 0.3, 0.5)
    assert hm > length + 1.0 / (n - 1)  # precondition: every node wet behind the jam
    loads = get_load(spec).loads_for(s, site)(r)
    f = total_forces(loads, s.nodes)[0] @ FLOW
    w = f[1] / s.area_per_node
    np.testing.assert_allclose(f[~s.fixed], f[1], rtol=1e-9)  # uniform
    net = solver.Net(s.nodes, s.fixed, s.elements, [solver.laws.linear(ea)])
    res = solver.solve(net, loads, tol=1e-10)
    assert res.converged
    y, z = res.displacements[:, 1], s.nodes[:, 2]
    sag = (3 * w * length / (64 * ea)) ** (1 / 3) * length
    assert y[n // 2] == pytest.approx(sag, rel=PARABOLA)
    np.testing.assert_allclose(y / y[n // 2], 4 * z * (length - z) / length**2, atol=SHAPE)


def test_jam_levels_are_the_flumes_discharge_steps():
    """On the printed 1:40 model the jam's levels pass 2, 3, ... 8 L/s through the 300 mm
    free section; a step held above the overflow is read at h/h_B = 1.1."""
    from printgen.inputs.prototype import load_prototype
    from printgen.scene import SceneOptions, build_scene
    from printgen.verification.preprint import load_keywords

    p, d = load_prototype(REALISTIC), reference_design_1_40()
    for porosity in (0.6, 0.8):
        _, kw = load_keywords(p, d, f"jam:porosity={porosity}")
        case, site = kw["load"], kw["site"]
        s = build_scene(d, SceneOptions(load=case))
        lv = case.levels_for(s, site)
        rec, _ = case.describe(s, site, lv)
        q = rec["discharge_l_per_s"]
        held = [x for x in DISCHARGES_L_PER_S if x <= q[-1] * (1 + ROOT)]
        assert lv[0] == 0 and np.all(np.diff(lv) > 0) and lv[-1] <= 1.1
        assert q[1:1 + len(held)] == pytest.approx(held, rel=ROOT)
        assert rec["flow_width_m"] == pytest.approx(0.3, rel=EXACT)
    assert len(lv) == 1 + len(DISCHARGES_L_PER_S)  # porosity 0.8: every step held


@pytest.mark.parametrize("given, match", [
    ("porosity=1.5", "porosity=1.5: jam's jam porosity must be a number from 0 to 0.99"),
    ("porosity=abc", "porosity=abc"),
    ("thickness_m=0", "thickness_m=0: .* from 0.01 to 50 m"),
    ("colour=3", "no parameter 'colour'")])
def test_jam_parameters_out_of_range_are_refused(given, match):
    with pytest.raises(InputError, match=match):
        with_params("jam", [given])


def test_cli_bad_load_param_exits_2_and_writes_nothing(tmp_path, capsys):
    from printgen.cli import main

    out = tmp_path / "out"
    code = main(["make", REALISTIC, "--scale", "40", "--out", out, "--loads",
                 "hydrostatic,jam", "--load-param", "porosity=-0.1"])
    assert code == 2 and not out.exists()
    assert "porosity=-0.1" in capsys.readouterr().err
    code = main(["make", REALISTIC, "--scale", "40", "--out", out, "--load-param", "porosity=0.5"])
    assert code == 2 and not out.exists()  # hydrostatic has no porosity


def test_cli_loads_and_load_params_make_specs():
    from printgen.cli import build_parser
    from printgen.commands.common import load_specs

    args = build_parser(["make"]).parse_args(
        ["make", "p.toml", "--scale", "40", "--loads", "hydrostatic,jam", "--load-param",
         "porosity=0.4"])
    main_spec, listed = load_specs(args)
    assert main_spec == "hydrostatic" and listed[0] == "hydrostatic"
    assert listed[1].startswith("jam:porosity=0.4,") and get_load(listed[1]).values[0] == (
        "porosity", 0.4)


@pytest.mark.slow
def test_case_readings_are_the_nominal_model_at_the_discharge_steps():
    """`make --loads ...,jam` writes expected-readings-jam.csv from these: the model's sweep
    at the jam's levels, the discharge beside each reading, sensors zeroed at h/h_B = 0; the
    report states the case's assumptions and readings."""
    from printgen.inputs.prototype import load_prototype
    from printgen.report.labfiles import _csv, case_file, case_readings
    from printgen.scene.readings import flume_units
    from printgen.verification.cases import case_runs

    c = case_runs(load_prototype(REALISTIC), reference_design_1_40(), "jam:porosity=0.8")
    r = case_readings(c.model, c.load["model"], flume_units(c.model.scene).length_mm)
    assert r["discharge_l_per_s"][1:] == pytest.approx(DISCHARGES_L_PER_S, rel=ROOT)
    assert r["mid_sensor_mm"][0] == 0 and np.all(np.diff(r["mid_sensor_mm"]) > 0)
    header = _csv(list(r), list(r.values())).splitlines()[0].split(",")
    assert header[:3] == ["h_over_hb", "water_depth_mm", "discharge_l_per_s"]
    assert case_file("jam") == "expected-readings-jam.csv"
    from printgen.report.html import Report
    from printgen.report.report import load_case_sections

    rep = Report("")
    load_case_sections(rep, SimpleNamespace(by_load={"jam": c}))
    html = rep.html()
    assert "What the campaign will see" in html and "discharge (L/s)" in html
    assert "loading: jam at each level" in html and "Ergun 1952" in html


@pytest.mark.parametrize("command", ["make", "verify", "series"])
def test_load_help_lists_every_registered_case(command):
    """--load's help is generated from the load-case registry: every case module appears in
    it, with its title, without editing the command line."""
    import argparse

    from printgen.barrier.loads import load_cases
    from printgen.cli import build_parser

    parser = build_parser([command])
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    text = " ".join(sub.choices[command].format_help().split())
    for name, case in load_cases().items():
        assert f"{name}: {' '.join(case.title.split())}" in text
