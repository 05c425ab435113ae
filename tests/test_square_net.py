"""The printed square net (issue 26 item 2): the simple barrier's square mesh is printed as a
square net, through the design, the mesh, the direct G-code, the slicer and the solver scene;
the diamond stays available through [model] pattern."""

from __future__ import annotations

import dataclasses
import json
import os
import subprocess

import numpy as np
import pytest
from conftest import coarse_simple_file, planned, require_shared, require_tool
from numpy.testing import assert_allclose
from proto_files import SIMPLE, write_variant

from printgen.barrier.patterns.square import square_factor
from printgen.errors import GeometryError
from printgen.inputs.materials import load_material
from printgen.inputs.printers import load_print_style, load_printer
from printgen.inputs.prototype import load_prototype
from printgen.parts.gcode import net_toolpath, net_volume_budget, write_gcode
from printgen.parts.gcode.toolpath import BORDER, STRAND_MINUS, STRAND_PLUS
from printgen.scene import build_scene

GEOM_TOL_MM = 1e-6  # float round-off on coordinates built from the graph
MESH_VOLUME_REL = 1e-6  # manifold's mesh volume vs the analytic plan area x thickness
STL_FLOAT_REL = 1e-5  # an STL stores float32 vertices: its volume moves by ~1e-6
VOLUME_TOL = 0.02  # read-back / checker volume within 2 % of the design (as test_gcode)
SLICE_TIMEOUT_S = 120
REDUCED_MM = (40.0, 30.0)  # a corner of the 300 x 100 mm net: the same strands, cheap to slice


@pytest.fixture(scope="module")
def simple():
    return planned(SIMPLE)


@pytest.fixture
def reduced(simple):
    net = dataclasses.replace(simple[1].net, width_mm=REDUCED_MM[0], height_mm=REDUCED_MM[1])
    return (net, load_printer(simple[1].printer), load_print_style(net.print_style),
            load_material(net.material))


def test_simple_barrier_is_printed_as_a_square_net(simple):
    p, d = simple
    n = d.net
    assert (n.pattern, n.mesh_x_mm, n.mesh_y_mm) == ("square", 5.0, 5.0)  # 200 mm / 40
    assert (n.width_mm, n.height_mm) == (300.0, 100.0)
    assert n.border_width_mm == n.strand.width_mm  # the edge rows are strands, no cables
    g = n.graph()
    assert len(g.nodes_mm) == len(build_scene(p).nodes) == 61 * 21
    assert len(g.strands) == 59 + 19
    assert set(np.unique(g.family)) == {-1, 0, 1}


def test_model_pattern_diamond_stays_available(tmp_path):
    path = write_variant(tmp_path, {("model", "pattern"): "diamond"}, base=SIMPLE)
    _, d = planned(path)
    assert d.net.pattern == "diamond"
    assert d.net.graph().strands[0].size > 2


def test_a_printed_square_net_needs_a_square_mesh(tmp_path):
    path = write_variant(tmp_path, {("model", "mesh_x_mm"): 5.0, ("model", "mesh_y_mm"): 6.0},
                         base=SIMPLE)
    with pytest.raises(GeometryError, match="square mesh needs mesh_x = mesh_y"):
        planned(path)


def test_square_membrane_law_is_one_strand_per_mesh(simple):
    """The printed net's law through the pattern's machinery: the model scene's strand law
    is the membrane law times the mesh across (`square.strand_law`)."""
    _, d = simple
    s = build_scene(d)
    n = d.net
    membrane = s.laws[0].slopes[0] * square_factor(n.mesh_x_mm * 1e-3)
    from printgen.scaling.section import net_membrane_law

    want = net_membrane_law(load_material(n.material), n.strand, n.mesh_y_mm * 1e-3,
                            n.mesh_x_mm * 1e-3, "square")[1][0]
    assert membrane == pytest.approx(want, rel=1e-12)


@pytest.mark.slow
@pytest.mark.parametrize("size", ["reduced", "full"])
def test_square_mesh_is_watertight_and_matches_its_analytic_volume(simple, size, tmp_path):
    pytest.importorskip("manifold3d")
    import trimesh

    from printgen.parts.export.stl import write_stl
    from printgen.parts.export.threemf import write_3mf
    from printgen.parts.geometry.solid import analytic_net_volume, net_solid

    net = simple[1].net
    if size == "reduced":
        net = dataclasses.replace(net, width_mm=REDUCED_MM[0], height_mm=REDUCED_MM[1])
    mesh = net_solid(net)
    assert mesh.is_watertight and mesh.is_winding_consistent
    assert mesh.volume == pytest.approx(analytic_net_volume(net), rel=MESH_VOLUME_REL)
    back = trimesh.load(write_stl(tmp_path / "net.stl", mesh, "net"))
    assert back.is_watertight and back.volume == pytest.approx(mesh.volume, rel=STL_FLOAT_REL)
    assert write_3mf(tmp_path / "net.3mf", [("net", mesh)]).stat().st_size > 0


def test_square_toolpath_lays_one_straight_bead_per_strand(reduced):
    net, printer, style, material = reduced
    g = net.graph()
    want = np.sort([np.hypot(*(g.nodes_mm[s[-1]] - g.nodes_mm[s[0]])) for s in g.strands])
    tp = net_toolpath(net, printer, style, material, crossing_flow_factor=1.0)
    lengths = tp.lengths_mm()
    assert len(tp.layer_z_mm) == net.strand.passes
    for k in range(len(tp.layer_z_mm)):
        strand = (tp.layer == k) & np.isin(tp.kind, (STRAND_PLUS, STRAND_MINUS))
        assert_allclose(np.sort(lengths[strand]), want, atol=GEOM_TOL_MM)  # one move a strand
        assert tp.kind[strand][0] == (STRAND_PLUS if k % 2 == 0 else STRAND_MINUS)
        assert np.count_nonzero(np.diff(tp.kind[strand])) == 1  # one family, then the other
        assert np.sum((tp.layer == k) & (tp.kind == BORDER)) == 4  # one bead: the edge strands
        ends = tp.xyz_mm[np.flatnonzero(strand)]
        d = np.abs(ends - tp.xyz_mm[np.flatnonzero(strand) - 1])[:, :2]
        assert np.all(np.min(d, axis=1) < GEOM_TOL_MM)  # up or across, never slanted
    for f in (1.0, 0.5):  # the crossings (w x w squares) at full or reduced flow
        tp = net_toolpath(net, printer, style, material, crossing_flow_factor=f)
        budget = net_volume_budget(net, style, crossing_flow_factor=f)
        assert abs(tp.volume_mm3 / budget.deposit_mm3 - 1) < VOLUME_TOL


def test_square_budget_solid_is_the_mesh_volume(reduced):
    pytest.importorskip("manifold3d")
    from printgen.parts.geometry.solid import net_solid

    net, _, style, _ = reduced
    assert net_volume_budget(net, style).solid_mm3 == pytest.approx(
        float(net_solid(net).volume), rel=MESH_VOLUME_REL)


def test_direct_square_gcode_passes_the_checker(simple, tmp_path):
    """The whole 300 x 100 mm net (on a reduced one the prime line alone is 13 % of the
    filament and the header's part-only total draws a WARN)."""
    net = simple[1].net
    printer, style = load_printer(simple[1].printer), load_print_style(net.print_style)
    material = load_material(net.material)
    script = require_shared("tools/gcode/check_gcode.py")
    p = material.print
    tp = net_toolpath(net, printer, style, material, crossing_flow_factor=1.0)
    path = write_gcode(tmp_path / "net.gcode", tp, printer, material)
    heights = net.strand.layer_heights_mm
    r = subprocess.run(
        ["python3", str(script), str(path), "--json", "-", "--quiet",
         "--bed", f"{printer.bed_x_mm:g}x{printer.bed_y_mm:g}x{printer.max_height_mm:g}",
         "--width", f"{net.strand.bead_width_mm}", "--area-model", "rect", "--tol", "0.15",
         "--layers", f"{len(heights)}", "--first-layer-height", f"{heights[0]}",
         "--layer-height", f"{heights[-1]}",
         "--min-hotend", f"{p.first_layer_nozzle_temperature_deg_c:g}",
         "--min-bed", f"{p.first_layer_bed_temperature_deg_c:g}",
         "--max-flow", f"{p.max_volumetric_flow_mm3_per_s:g}",
         "--expect-volume",
         f"{net_volume_budget(net, style, crossing_flow_factor=1.0).deposit_mm3:.3f}",
         "--volume-tol", f"{VOLUME_TOL}"], capture_output=True, text=True, check=False)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    rep = json.loads(r.stdout[r.stdout.index("{"):r.stdout.rindex("}") + 1])
    bad = [c for c in rep["checks"] if c["status"] != "PASS"]
    assert not bad, bad
    assert rep["strand_section"]["len_within_tol_frac"] == 1.0  # every move is w x h exactly


def test_prusaslicer_slices_the_square_net(reduced, tmp_path):
    pytest.importorskip("manifold3d")
    from printgen.parts.geometry.solid import net_solid
    from printgen.parts.slicer import write_prusa_ini

    require_tool("prusa-slicer")
    script = require_shared("tools/gcode/slice_check.sh")
    net, printer, style, material = reduced
    ini = write_prusa_ini(tmp_path / "net.ini", "net", net, printer, style, material)
    stl = tmp_path / "net.stl"
    net_solid(net).export(stl)
    env = dict(os.environ, OUT_DIR=str(tmp_path), PYTHON=os.environ.get("PYTHON", "python3"))
    r = subprocess.run(["bash", str(script), str(stl), str(ini), "--width",
                        f"{net.strand.width_mm}", "--area-model", "stadium", "--layers",
                        f"{len(net.strand.layer_heights_mm)}", "--max-flow",
                        f"{material.print.max_volumetric_flow_mm3_per_s:g}"],
                       capture_output=True, text=True, env=env, timeout=SLICE_TIMEOUT_S,
                       check=False)
    summary = r.stdout.strip().splitlines()[-1] if r.stdout.strip() else r.stderr
    assert r.returncode == 0 and summary.startswith("SLICE-CHECK OK"), summary


PANEL_REL = 1e-6  # the solver's panel tolerance is 1e-9 of the strand force: far below this
# Free mode: the ties that hold each free node (panel.HOLD_RATIO) also resist its travel along
# the load, which `hold_share` (x only) does not count: 0.4 % of the clamp force here.
FREE_HOLD_REL = 0.01


@pytest.mark.slow
@pytest.mark.parametrize("mode", ["blocked", "free"])
def test_virtual_panel_of_the_square_net_reads_its_membrane_law(simple, mode):
    """The same panel machinery as the diamond (`scene.panel`): the designed square
    strands, tested as a panel, give the membrane law the design priced (one strand per mesh
    across, `square.membrane_factor`), times (nx + 1) / nx for the panel's two edge strands
    on a width of nx meshes; free or blocked alike (a square net has no Poisson effect)."""
    from printgen.scaling.section import net_membrane_law
    from printgen.scene.panel import PanelTest, lattice_size, simulate

    _, d = simple
    n = d.net
    a = n.mesh_x_mm * 1e-3
    law = build_scene(d).laws[0]
    t = PanelTest(a, a, 10 * a, 8 * a, mode, "square")
    nx = round(lattice_size(t)[1] / a)
    strains = np.array([0.01, 0.05, 0.2])
    curve = simulate(law, t, strains)
    knees, slopes, _ = net_membrane_law(load_material(n.material), n.strand, a, a, "square")
    from printgen.inputs.laws import piecewise_linear

    want = piecewise_linear(strains, knees, slopes) * (nx + 1) / nx
    assert_allclose(curve.force_per_width, want,
                    rtol=PANEL_REL if mode == "blocked" else FREE_HOLD_REL)
    assert curve.hold_share < PANEL_REL  # no mechanism: nothing moves across the load


@pytest.fixture(scope="module")
def coarse_simple(tmp_path_factory):
    """The simple barrier on a mesh twice as coarse (the test's budget: 31 x 11 nodes), its
    printed square net at 10 mm; the same scene as examples/simple_barrier.toml otherwise."""
    return planned(coarse_simple_file(tmp_path_factory.mktemp("square")))


@pytest.mark.slow
def test_verification_of_the_square_net_converges_at_every_level(coarse_simple):
    """Prototype and printed square net solved at every level of the sweep (h / h_B = 0 to
    1.1 by 0.05), the model with its printed edge frame and pulling sensor wires."""
    from printgen.verification.preprint import levels, verify

    p, d = coarse_simple
    assert d.net.pattern == "square"
    v = verify(p, d)
    assert not v.prototype.failed and not v.model.failed
    assert v.compared == v.asked == len(levels())
    assert any(row[0] == "printed border frame" for row in v.model.scene.assumptions)


RING_QUADRATURE = 1e-4  # the analytic area's polar-grid integral over each ring (1.3e-5 seen)


@pytest.mark.slow
def test_square_net_with_border_cables_has_loops_and_lays_its_volume(tmp_path):
    """The simple barrier with border cables: a two-bead frame with a loop on every edge node
    (the cables thread them), a watertight mesh, and a direct G-code laying the mesh's volume."""
    pytest.importorskip("manifold3d")
    from printgen.parts.geometry.attach import attachment_for
    from printgen.parts.geometry.solid import analytic_net_volume, net_solid

    path = tmp_path / "bordered.toml"
    path.write_text(SIMPLE.read_text() + "\n[border]\ndiameter_mm = 24.0\nmodulus_gpa = 100.0\n")
    _, d = planned(path)
    assert d.net.pattern == "square" and d.net.border_width_mm == 2 * d.net.strand.bead_width_mm
    n = dataclasses.replace(d.net, width_mm=REDUCED_MM[0], height_mm=REDUCED_MM[1])
    printer = load_printer(d.printer)
    att = attachment_for(d, hole_compensation_mm=printer.hole_compensation_mm)
    mesh = net_solid(n, att)
    assert mesh.is_watertight
    assert mesh.volume == pytest.approx(analytic_net_volume(n, att), rel=RING_QUADRATURE)
    tp = net_toolpath(n, printer, load_print_style(n.print_style), load_material(n.material),
                      attachment=att)
    assert abs(tp.volume_mm3 / mesh.volume - 1) < VOLUME_TOL


def test_square_prototype_with_unequal_sides_is_refused(tmp_path):
    """A square prototype mesh is its side both ways: unequal mesh_x and mesh_y are refused
    when the file is read, naming both values (the graph would silently use mesh_x)."""
    from printgen.errors import InputError

    bad = write_variant(tmp_path, {("net", "mesh_y_m"): 0.25}, base=SIMPLE)
    with pytest.raises(InputError,
                       match=r'pattern "square" needs mesh_x_m = mesh_y_m.*0\.2 x 0\.25'):
        load_prototype(bad)
