"""printgen/barrier: the net patterns and the load cases as data, found by their registries.
A new pattern or load case is one module in its folder plus a test here."""

from __future__ import annotations

import dataclasses
import json
import math
from types import SimpleNamespace

import numpy as np
import pytest

import printgen.barrier.loads as loads_package
import printgen.barrier.patterns as patterns_package
from printgen.barrier.loads import DEFAULT, FLOW, Site, case_names, get_load, load_cases
from printgen.barrier.patterns import get_pattern, patterns
from printgen.barrier.registry import names
from printgen.cli import build_parser
from printgen.errors import InputError
from printgen.solver.loads import total_forces
from printgen.units import RHO_WATER, G

EXACT = 1e-12  # closed-form arithmetic, round-off only
PANEL_MM = (61.0, 47.0, 12.0, 14.0)  # width, height, mesh_x, mesh_y: an odd-sized panel


def test_registries_name_each_module_as_its_entry():
    """The command line lists the modules' names without importing them: they must be the
    entries' names."""
    assert names(patterns_package) == list(patterns())
    assert names(loads_package) == case_names() == list(load_cases())
    assert {"diamond", "square"} <= set(patterns())
    assert {"drag", "flow", "jam", DEFAULT} <= set(load_cases())


def test_unknown_names_are_errors_listing_the_known_ones():
    with pytest.raises(InputError, match="'hexagon' is not one of .*diamond, .*square"):
        get_pattern("hexagon")
    with pytest.raises(InputError, match="'avalanche' is not one of .*drag, .*hydrostatic"):
        get_load("avalanche")
    assert get_pattern("water-drop").name == "diamond"  # drawn as diamonds (the assumption says)
    assert get_load(None).name == DEFAULT


@pytest.mark.parametrize("name", ["diamond", "square"])
def test_node_count_is_the_graphs(name):
    """The budget counts nodes without building the graph: the same count."""
    pat = get_pattern(name)
    for w, h, ax, ay in (PANEL_MM, (330.0, 100.0, 20.6, 9.4), (300.0, 100.0, 10.0, 10.0)):
        assert pat.nodes(w, h, ax, ay) == len(pat.graph(w, h, ax, ay).nodes_mm)


@pytest.mark.parametrize("name", ["diamond", "square"])
def test_graph_spans_the_rounded_panel(name):
    """The graph's size is the panel rounded by the pattern's `span` (the half-mesh rule for
    the diamond, whole meshes for the square)."""
    pat = get_pattern(name)
    w, h, ax, ay = PANEL_MM
    size = pat.graph(w, h, ax, ay).size_mm
    mesh_up = ay if name == "diamond" else ax  # the square's mesh is mesh_x both ways
    assert size == pytest.approx((pat.span(w, ax), pat.span(h, mesh_up)), rel=EXACT)


@pytest.mark.parametrize("name", ["diamond", "square"])
def test_strand_law_inverts_the_membrane_factor(name):
    """A strand of axial stiffness EA gives the membrane slope EA x factor; the strand law of
    that membrane law is EA again, its knee the strand's strain at the net's knee."""
    pat = get_pattern(name)
    along, across, ea, knee = 9.4e-3, 20.6e-3, 120.0, 0.1
    membrane = ea * pat.membrane_factor(along, across)
    law = pat.strand_law((knee,), (membrane, 2 * membrane), along, across)
    knees, slopes = law.knees, law.slopes
    assert slopes == pytest.approx((ea, 2 * ea), rel=EXACT)
    sin2 = along**2 / (along**2 + across**2) if name == "diamond" else 1.0
    assert knees == pytest.approx((knee * sin2,), rel=EXACT)


def test_square_membrane_and_strand_force_are_one_strand_per_mesh():
    sq = get_pattern("square")
    assert sq.membrane_factor(0.3, 0.2) == pytest.approx(5.0, rel=EXACT)
    assert sq.strand_force(100.0, 0.3, 0.2) == pytest.approx(20.0, rel=EXACT)
    dia = get_pattern("diamond")  # square diamond: 2 strands per 0.2 m at 45 degrees
    assert dia.strand_force(100.0, 0.2, 0.2) == pytest.approx(100 * 0.2 / math.sqrt(2),
                                                              rel=EXACT)


def test_pattern_specific_rules_are_the_patterns(monkeypatch):
    """What differs between patterns outside the graph and the laws (the mesh's name, the mesh
    it may have, whether the virtual panel test models it) is each pattern's own data: a new
    pattern states them (no default, so it is not quietly taken for a diamond)."""
    from printgen.barrier.patterns import NetPattern
    from printgen.errors import GeometryError
    from printgen.scaling.testpieces import panel_for

    for p in patterns().values():
        p.check_mesh(0.2, 0.2, "net")  # every pattern takes a mesh equal both ways
    assert [get_pattern(n).mesh_name for n in ("square", "diamond", "water-drop")] == [
        "mesh side", "mesh diagonal", "mesh diagonal"]
    get_pattern("diamond").check_mesh(0.2, 0.3, "net")
    with pytest.raises(GeometryError, match="printed net: a square mesh needs mesh_x = mesh_y"):
        get_pattern("square").check_mesh(0.2, 0.3, "printed net")
    square_pattern = get_pattern("square")
    with pytest.raises(TypeError, match="mesh_name"):
        NetPattern("new", *(getattr(square_pattern, f) for f in (
            "graph", "membrane_factor", "strand_law", "strand_force", "span", "nodes")))
    # both registered patterns have a test panel; one without is refused by name
    from printgen.barrier.patterns import panel_test_patterns

    assert set(panel_test_patterns()) == {"diamond", "square"}
    untested = dataclasses.replace(square_pattern, name="new", panel_test=False)
    monkeypatch.setattr("printgen.scaling.testpieces.get_pattern", lambda name: untested)
    new = SimpleNamespace(net=SimpleNamespace(pattern="new"))
    with pytest.raises(GeometryError, match="needs a diamond or square net; this design's net "
                                            r"is 'new' \(the virtual panel test models diamonds "
                                            "and squares only"):
        panel_for(new, "short", 50.0, 30.0)


def _flat_scene(n: int = 5, height: float = 1.0):
    """A vertical column of n nodes 0..height (z), the bottom one anchored: what a load case
    reads of a BarrierScene."""
    z = np.linspace(0.0, height, n)
    nodes = np.column_stack([np.zeros(n), np.zeros(n), z])
    fixed = np.zeros(n, bool)
    fixed[0] = True
    elements = np.column_stack([np.arange(n - 1), np.arange(1, n)])
    return SimpleNamespace(nodes=nodes, fixed=fixed, elements=elements, area_per_node=0.25,
                           height=height)


def test_hydrostatic_load_is_rho_g_depth_area():
    s = _flat_scene()
    (load,) = get_load("hydrostatic").loads(s, None)(1.0)
    f, _ = total_forces([load], s.nodes)
    depth = np.clip(1.0 - s.nodes[:, 2], 0, None)
    want = RHO_WATER * G * depth * s.area_per_node * (~s.fixed)
    np.testing.assert_allclose(f @ FLOW, want, rtol=EXACT, atol=EXACT)


def test_drag_is_hydrostatic_plus_half_rho_v2_l_d_when_all_is_wet():
    """Water far above every node: each free node carries 0.5 rho v^2 l d, l the strand length
    per node (barrier-physics.md section 3), on top of the same hydrostatic load."""
    s, site = _flat_scene(), Site(velocity=2.0, strand_diameter=0.01)
    r = 3.0  # level 3 h_B: every node wet, past the ramp
    still = get_load("hydrostatic").loads(s, site)(r)
    both = get_load("drag").loads(s, site)(r)
    f_still, _ = total_forces(still, s.nodes)
    f_both, _ = total_forces(both, s.nodes)
    per_node = 0.5 * RHO_WATER * site.velocity**2 * (1.0 / 5) * site.strand_diameter
    want = per_node * (~s.fixed)
    np.testing.assert_allclose((f_both - f_still) @ FLOW, want, rtol=EXACT, atol=EXACT)


def test_a_load_case_states_its_assumptions_in_the_scenes(design_1_40):
    from printgen.scene import SceneOptions, build_scene

    plain = build_scene(design_1_40)
    dragged = build_scene(design_1_40, SceneOptions(load="drag"))
    what = [a[0] for a in dragged.assumptions]
    assert "loading: drag" in what and "loading" in what
    assert "loading: drag" not in [a[0] for a in plain.assumptions]


def test_net_design_pattern_defaults_to_diamond_and_is_read_back(design_1_40):
    from printgen.scaling.design_file import design_from_dict

    rec = json.loads(json.dumps(design_1_40.to_dict()))  # as design.json holds it
    assert rec["net"]["pattern"] == "diamond"
    del rec["net"]["pattern"]  # a design.json written before the field existed
    assert design_from_dict(rec).net.pattern == "diamond"
    rec["net"]["pattern"] = "hexagon"
    with pytest.raises(InputError, match="hexagon"):
        design_from_dict(rec)
    square = dataclasses.replace(design_1_40.net, pattern="square", mesh_y_mm=20.6)
    assert len(square.graph().nodes_mm) == get_pattern("square").nodes(330.0, 100.0, 20.6, 20.6)


@pytest.mark.parametrize("command", ["make", "verify"])
def test_cli_load_and_its_drag_alias(command):
    extra = ["--design", "d.json"] if command == "verify" else []
    parse = build_parser([command]).parse_args
    base = [command, "p.toml", "--scale", "40", *extra]
    assert parse(base).load is None
    assert parse([*base, "--load", "drag"]).load == "drag"
    assert parse([*base, "--drag"]).load == "drag"
    from printgen.cli import UsageError

    with pytest.raises(UsageError, match="invalid choice: 'avalanche'"):  # one line, exit 2
        parse([*base, "--load", "avalanche"])
