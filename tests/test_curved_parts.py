"""Curved-strand nets printed: the design's wave, the watertight mesh along the waves, the
direct G-code of the curves (read back and checked by ../shared's checker), PrusaSlicer's
beads on a curved strand, and the print time and mass against the straight net."""

from __future__ import annotations

import dataclasses
import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest
from conftest import EXAMPLES, reference_design_1_40, require_shared, require_tool
from numpy.testing import assert_allclose

from printgen.barrier.patterns.curved import MIN_RADIUS_BEADS, chord, spacing
from printgen.errors import GeometryError, InputError
from printgen.inputs.materials import load_material
from printgen.inputs.printers import load_print_style, load_printer
from printgen.parts.gcode import net_toolpath, net_volume_budget, read_gcode, write_gcode
from printgen.parts.gcode.price import wave_price
from printgen.parts.gcode.toolpath import STRAND_MINUS, STRAND_PLUS
from printgen.parts.geometry.lattice import crossing_sin
from printgen.parts.geometry.wave import (
    CHORD_TOL_MM,
    node_tangents,
    wave_length,
    waved_areas,
    waved_strands,
)
from printgen.scaling.design_file import design_from_dict, load_design
from printgen.scaling.record import Design, NetDesign, Wave

WAVE = Wave(1.5, 1)  # the top of the 1.0-1.5 mm range asked of the 1:40 net: the tightest
LOW_WAVE = Wave(1.0, 1)
REDUCED_MM = (40.0, 60.0)  # a piece of the 1:40 net: the same strands, cheap to mesh and slice
MESH_VS_ANALYTIC = 1e-3  # mesh vs analytic volume: the polylines sit within 0.01 mm of the
# waves on 0.6 mm strands (measured 7e-5 on the 1:40 net)
VOLUME_TOL = 0.02  # the brief: G-code volume within 2 % of the STL's / of the design
LENGTH_REL = 1e-9  # closed-form arc length vs a fine trapezoid rule (1e6 points)
ANGLE_TOL = 1e-9  # float round-off on tangents built from the graph
DEPOSIT_REL = 1e-3  # toolpath volume vs its budget: only the crossing spans' ends differ
# (a span is placed along the tangent at the junction, where the wave has no curvature)
SECTION_TOL = 0.15  # slicers.md: a strand's bead within 15 % of its section (the checker's)
SLICE_TIMEOUT_S = 120


def _setup(net: NetDesign):
    d = reference_design_1_40()
    return (load_printer(d.printer), load_print_style(net.print_style),
            load_material(net.material))


def _example_net() -> NetDesign:
    """The net `printgen make examples/realistic_barrier.toml -s 40` designs (its design.json):
    the 20.6 x 9.4 mm TPE diamond net, 0.6 mm strands of two layers, on 329.6 x 98.7 mm."""
    return dataclasses.replace(reference_design_1_40().net, width_mm=329.6, height_mm=98.7,
                               strand=dataclasses.replace(reference_design_1_40().net.strand,
                                                          layer_heights_mm=(0.35, 0.3)))


def _reduced(wave: Wave | None = WAVE) -> NetDesign:
    return dataclasses.replace(reference_design_1_40().net, width_mm=REDUCED_MM[0],
                               height_mm=REDUCED_MM[1], wave=wave)


# ----------------------------------------------------------------------------- the record
def test_a_straight_design_has_no_wave_in_its_record():
    """A design file without a wave reads as straight strands and writes no wave key: every
    existing design.json reads and writes as before."""
    path = EXAMPLES / "paper_1_40" / "design.json"
    d = load_design(path)
    assert d.net.wave is None
    rec = d.to_dict()
    assert "wave" not in rec["net"]
    on_file = json.loads(path.read_text())
    rec = json.loads(json.dumps(rec))
    assert rec["net"] == {**on_file["net"], "pattern": "diamond"}  # the file predates patterns
    assert Design.from_record(rec) == d


def test_a_wave_round_trips_through_the_design_file(tmp_path):
    d = dataclasses.replace(reference_design_1_40(),
                            net=dataclasses.replace(reference_design_1_40().net, wave=WAVE))
    path = tmp_path / "design.json"
    path.write_text(json.dumps(d.to_dict()))
    back = load_design(path)
    assert back.net.wave == WAVE and back == d
    assert d.to_dict()["net"]["wave"] == {"amplitude_mm": 1.5, "half_waves": 1}


def _record() -> dict:
    """The 1:40 reference design as its design.json holds it (lists, not tuples)."""
    return json.loads(json.dumps(reference_design_1_40().to_dict()))


def _limits():
    """The 1:40 mesh's strand chord and spacing, and its strands' bead (mm)."""
    net = reference_design_1_40().net
    return (chord("diamond", net.mesh_y_mm, net.mesh_x_mm),
            spacing("diamond", net.mesh_y_mm, net.mesh_x_mm), net.strand.bead_width_mm)


def test_a_wave_bending_tighter_than_a_bead_is_refused_with_the_largest_amplitude():
    length, _, bead = _limits()
    n = 5  # 1 mm over 5 half-waves of an 11.3 mm chord bends on 0.52 mm < one 0.6 mm bead
    k = n * math.pi / length
    most = 1 / (k * k * MIN_RADIUS_BEADS * bead)  # the radius 1 / (a k^2) at the limit
    rec = _record()
    rec["net"]["wave"] = {"amplitude_mm": 1.0, "half_waves": n}
    with pytest.raises(InputError) as err:
        design_from_dict(rec)
    msg = str(err.value)
    assert "printable minimum of 1 bead width (0.6 mm)" in msg
    assert f"amplitude of at most {most:.3g} mm" in msg and "net wave" in msg


def test_a_wave_wider_than_the_gap_between_strands_is_refused():
    _, gap, bead = _limits()
    rec = _record()
    rec["net"]["wave"] = {"amplitude_mm": 4.5, "half_waves": 1}
    with pytest.raises(InputError, match="neighbouring strands would fuse") as err:
        design_from_dict(rec)
    assert f"at most {(gap - bead) / 2:.3g} mm" in str(err.value)


@pytest.mark.parametrize(("wave", "message"), [
    ({"amplitude_mm": 0.0, "half_waves": 1}, "amplitude_mm"),
    ({"amplitude_mm": 1.0, "half_waves": 0}, "half_waves"),
    ({"amplitude_mm": 1.0}, r"missing keys \['half_waves'\]"),
    ({"amplitude_mm": 1.0, "half_waves": 1, "phase": 0}, "unknown keys"),
    ("1.0", "expected a table of Wave fields"),
])
def test_bad_wave_entries_are_input_errors(wave, message):
    rec = _record()
    rec["net"]["wave"] = wave
    with pytest.raises(InputError, match=message):
        design_from_dict(rec)


# ----------------------------------------------------------------------------- the waves
def test_wave_length_is_the_arc_length():
    x = np.linspace(0.0, 11.3, 1_000_001)
    for w in (WAVE, Wave(0.7, 3)):
        y = w.amplitude_mm * np.sin(w.half_waves * np.pi * x / 11.3)
        assert_allclose(wave_length(11.3, w), np.hypot(np.diff(x), np.diff(y)).sum(),
                        rtol=LENGTH_REL)
    assert_allclose(wave_length(11.3, Wave(1e-9, 1)), 11.3, rtol=LENGTH_REL)  # straight limit


@pytest.mark.parametrize("offset", [0.0, 0.3, -0.6])
def test_polylines_stay_within_the_chord_tolerance(offset):
    g = _reduced().graph()
    ws = waved_strands(g, WAVE)[len(g.strands) // 2]
    p = ws.polyline(0.0, ws.length, offset)
    true = ws.points(np.linspace(0.0, ws.length, 200_001), offset)  # 0.0002 mm apart
    mid = (p[1:] + p[:-1]) / 2
    gap = [np.min(np.hypot(*(true - m).T)) for m in mid]
    assert max(gap) <= CHORD_TOL_MM
    assert_allclose(ws.points(ws.t_nodes), g.nodes_mm[g.strands[len(g.strands) // 2]],
                    atol=ANGLE_TOL)  # through its junctions


def test_junctions_keep_the_straight_nets_crossing_angle():
    """Both strands' tangents turn the same way at each junction, by atan(a k): the crossing
    angle is the straight net's."""
    g = _reduced().graph()
    tangents = node_tangents(g, WAVE)
    straight = crossing_sin(g)
    junctions = {int(n) for s in g.strands for n in s[1:-1]}
    assert junctions
    for node in junctions:
        t1, t2 = tangents[node]
        assert_allclose(abs(t1[0] * t2[1] - t1[1] * t2[0]), straight, atol=ANGLE_TOL)
    ws = waved_strands(g, WAVE)[0]
    k = WAVE.half_waves * math.pi / float(np.diff(ws.t_nodes)[0])
    t0 = ws.frame(0.0)[0]
    turn = math.atan2(ws.u[0] * t0[1] - ws.u[1] * t0[0], float(ws.u @ t0))
    assert_allclose(abs(turn), math.atan(WAVE.amplitude_mm * k), atol=ANGLE_TOL)


# ----------------------------------------------------------------------------- the mesh
def _mesh_case(net: NetDesign, with_loops: bool):
    from printgen.parts.geometry.solid import analytic_net_volume, attachment_for, net_solid

    d = dataclasses.replace(reference_design_1_40(), net=net)
    att = attachment_for(d, hole_compensation_mm=_setup(net)[0].hole_compensation_mm) \
        if with_loops else None
    return net_solid(net, att), analytic_net_volume(net, att), att


@pytest.mark.parametrize("wave", [LOW_WAVE, WAVE], ids=["1.0mm", "1.5mm"])
def test_curved_mesh_is_watertight_with_the_analytic_bead_volume(wave):
    pytest.importorskip("manifold3d")
    net = _reduced(wave)
    mesh, analytic, _ = _mesh_case(net, with_loops=False)
    assert mesh.is_watertight and mesh.is_winding_consistent
    assert len(mesh.split(only_watertight=False)) == 1
    assert abs(mesh.volume / analytic - 1) < MESH_VS_ANALYTIC
    # the analytic strand term is the path length x section: the polylines' own lengths
    g = net.graph()
    polylines = sum(float(np.hypot(*np.diff(ws.polyline(0.0, ws.length), axis=0).T).sum())
                    for ws in waved_strands(g, wave))
    assert_allclose(waved_areas(net, g).strands, polylines * net.strand.width_mm,
                    rtol=MESH_VS_ANALYTIC)
    straight, _, _ = _mesh_case(_reduced(None), with_loops=False)
    assert mesh.volume > straight.volume  # longer strands, same crossings


@pytest.mark.slow
@pytest.mark.parametrize("wave", [LOW_WAVE, WAVE], ids=["1.0mm", "1.5mm"])
def test_curved_1_40_net_with_loops_is_watertight_with_its_analytic_volume(wave):
    pytest.importorskip("manifold3d")
    net = dataclasses.replace(_example_net(), wave=wave)
    mesh, analytic, _ = _mesh_case(net, with_loops=True)
    assert mesh.is_watertight
    assert abs(mesh.volume / analytic - 1) < MESH_VS_ANALYTIC


# ----------------------------------------------------------------------------- the G-code
def test_waved_beads_follow_the_wave_and_lay_their_budget():
    net = _reduced()
    printer, style, material = _setup(net)
    tp = net_toolpath(net, printer, style, material)
    budget = net_volume_budget(net, style)
    assert_allclose(tp.volume_mm3, budget.deposit_mm3, rtol=DEPOSIT_REL)
    strand = np.isin(tp.kind, (STRAND_PLUS, STRAND_MINUS)) & tp.extruding
    # every strand move is a short chord of the wave, never a straight strand
    lengths = tp.lengths_mm()[strand]
    assert lengths.max() < 1.0 < float(np.diff(waved_strands(net.graph(), WAVE)[0].t_nodes)[0])
    # and the toolpath's points lie on the waved centre lines (one bead per strand)
    g = net.graph()
    true = np.vstack([ws.points(np.linspace(0.0, ws.length, 20_001))
                      for ws in waved_strands(g, WAVE)])
    rot, shift = _placement(tp, g)
    pts = (tp.xyz_mm[strand, :2] - shift) @ rot
    pick = pts[:: max(1, len(pts) // 400)]
    gap = [np.min(np.hypot(*(true - p).T)) for p in pick]
    assert max(gap) < 2 * CHORD_TOL_MM + 1e-3  # written with 3 decimals


def _placement(tp, g):
    """(rotation, shift) taking part coordinates to the toolpath's bed coordinates: the
    part's centre on the toolpath's, turned by the angle of the first border move."""
    from printgen.parts.gcode.toolpath import BORDER

    b = int(np.flatnonzero(tp.kind == BORDER)[0])  # along the panel's bottom edge, +x
    d = tp.xyz_mm[b, :2] - tp.xyz_mm[b - 1, :2]
    a = math.atan2(d[1], d[0])
    rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    lo, hi = tp.bounds_mm()[:, :2]
    centre = (lo + hi) / 2
    return rot, centre - rot @ (np.array(g.size_mm) / 2)


@pytest.mark.parametrize(("wave", "message"), [
    (Wave(1.0, 5), "printable minimum of 1 bead width"),  # the pattern's limit
    (Wave(2.5, 1), "swings its centre line 0.437 mm past the panel edge"),  # the frame's
])
def test_unprintable_waves_fail_before_any_part_is_written(wave, message, tmp_path):
    """A net built in code (not read from a file) meets the same limits in the mesh and the
    G-code: the frame's too (2.5 mm passes the pattern's band check, 5.6 < 8.55 mm, but
    swings the strands at the edge out of the 1.2 mm frame)."""
    from printgen.parts.geometry.solid import net_solid

    net = _reduced(wave)
    printer, style, material = _setup(net)
    out = tmp_path / "net.gcode"
    with pytest.raises(GeometryError, match=message):
        write_gcode(out, net_toolpath(net, printer, style, material), printer, material)
    with pytest.raises(GeometryError, match=message):
        net_solid(net)
    assert not out.exists()


def _checker(path, *args):
    script = require_shared("tools/gcode/check_gcode.py")
    r = subprocess.run([sys.executable, str(script), str(path), "--json", "-", *args],
                       check=False, capture_output=True, text=True, timeout=SLICE_TIMEOUT_S)
    return r.returncode, json.loads(r.stdout), r.stderr.strip().splitlines()[-1]


@pytest.mark.slow
def test_direct_curved_net_lays_the_stl_volume_and_passes_the_checker(tmp_path):
    """The 1:40 example's net with a 1.5 mm wave and its loops (as make writes it): read
    back, the G-code lays the STL's volume within 2 %, and the independent checker passes it
    with the material's flow limit and the bead section on every move."""
    pytest.importorskip("manifold3d")
    net = dataclasses.replace(_example_net(), wave=WAVE)
    mesh, _, att = _mesh_case(net, with_loops=True)
    printer, style, material = _setup(net)
    tp = net_toolpath(net, printer, style, material, attachment=att)
    path = write_gcode(tmp_path / "net.gcode", tp, printer, material)
    rb = read_gcode(path, filament_diameter_mm=printer.filament_diameter_mm)
    assert abs(rb.volume_mm3 / mesh.volume - 1) < VOLUME_TOL
    p = material.print
    heights = net.strand.layer_heights_mm
    rc, rep, summary = _checker(
        path, "--bed", f"{printer.bed_x_mm:g}x{printer.bed_y_mm:g}x{printer.max_height_mm:g}",
        "--width", f"{net.strand.bead_width_mm}", "--area-model", "rect",
        "--tol", f"{SECTION_TOL}", "--layers", f"{len(heights)}",
        "--first-layer-height", f"{heights[0]}", "--layer-height", f"{heights[-1]}",
        "--min-hotend", f"{p.first_layer_nozzle_temperature_deg_c:g}",
        "--min-bed", f"{p.first_layer_bed_temperature_deg_c:g}",
        "--max-flow", f"{p.max_volumetric_flow_mm3_per_s:g}",
        "--expect-volume", f"{mesh.volume:.3f}", "--volume-tol", f"{VOLUME_TOL}")
    assert rc == 0, summary
    bad = [c for c in rep["checks"] if c["status"] != "PASS"]
    assert not bad, bad


# ----------------------------------------------------------------------------- the slicer
@pytest.mark.slow
def test_prusaslicer_prints_a_curved_strand_as_one_bead(tmp_path):
    """The net's PrusaSlicer settings, unchanged, slice a curved net: at the crest of every
    inner strand segment, each layer has exactly one extrusion across the strand, of the
    strand's stadium section (0.6 x h, within the checker's 15 %)."""
    require_tool("prusa-slicer")
    script = require_shared("tools/gcode/slice_check.sh")
    pytest.importorskip("manifold3d")
    from printgen.parts.geometry.solid import net_solid
    from printgen.parts.slicer import write_prusa_ini

    net = _reduced()
    printer, style, material = _setup(net)
    ini = write_prusa_ini(tmp_path / "net.ini", "net", net, printer, style, material)
    mesh = net_solid(net)
    mesh.export(tmp_path / "net.stl")
    env = dict(os.environ, OUT_DIR=str(tmp_path), PYTHON=os.environ.get("PYTHON", "python3"))
    r = subprocess.run(["bash", str(script), str(tmp_path / "net.stl"), str(ini),
                        "--width", f"{net.strand.width_mm}", "--area-model", "stadium",
                        "--layers", f"{len(net.strand.layer_heights_mm)}",
                        "--max-flow", f"{material.print.max_volumetric_flow_mm3_per_s:g}"],
                       capture_output=True, text=True, env=env, timeout=SLICE_TIMEOUT_S,
                       check=False)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    rb = read_gcode(tmp_path / "net.prusa.gcode",
                    filament_diameter_mm=printer.filament_diameter_mm)
    tp = rb.toolpath
    ext = np.flatnonzero(tp.extruding)
    # PrusaSlicer centres the part: the extrusions' box centre is the mesh's
    shift = rb.bounds_mm[:, :2].mean(axis=0) - mesh.bounds[:, :2].mean(axis=0)
    a, b = tp.xyz_mm[ext - 1, :2] - shift, tp.xyz_mm[ext, :2] - shift
    g, w = net.graph(), net.strand.width_mm
    heights = np.diff(np.concatenate([[0.0], tp.layer_z_mm]))
    counts = []
    for ws in waved_strands(g, WAVE):
        for t0, t1 in zip(ws.t_nodes[:-1], ws.t_nodes[1:], strict=True):
            c = ws.points(np.array([(t0 + t1) / 2]))[0]  # the crest
            if min(*c, *(np.array(g.size_mm) - c)) < 2 * net.border_width_mm:
                continue  # the border's beads run beside it
            normal = ws.frame((t0 + t1) / 2)[1]
            p, q = c - 1.5 * w * normal, c + 1.5 * w * normal  # across the strand
            hit = (_side(p, q, a) != _side(p, q, b)) & (_side(a, b, p) != _side(a, b, q))
            for k, h in enumerate(heights):
                sel = hit & (tp.layer[ext] == k)
                counts.append(int(sel.sum()))
                stadium = (w * h - (1 - math.pi / 4) * h * h) / h  # its rectangle's width
                assert np.all(np.abs(tp.width_mm[ext][sel] / stadium - 1) < SECTION_TOL)
    assert len(counts) > 100 and set(counts) == {1}


def _side(o, u, v):
    """Sign of the turn o -> u -> v (arrays of points broadcast)."""
    return np.sign((u[..., 0] - o[..., 0]) * (v[..., 1] - o[..., 1])
                   - (u[..., 1] - o[..., 1]) * (v[..., 0] - o[..., 0]))


# ----------------------------------------------------------------------------- the price
@pytest.mark.slow
def test_curved_net_costs_its_extra_path_in_time_and_mass():
    """The 1:40 example's net with 1.0 and 1.5 mm waves against its straight net: more time
    and mass, the mass by the extruded volume's ratio, and more with the larger wave."""
    net = _example_net()
    printer, style, material = _setup(net)
    low, high = (wave_price(net, printer, style, material, wave=w) for w in (LOW_WAVE, WAVE))
    for price in (low, high):
        assert price.time_ratio > 1 and price.mass_ratio > 1
        assert_allclose(price.mass_ratio, price.curved.volume_mm3 / price.straight.volume_mm3,
                        rtol=1e-12)
        rec = price.to_record()
        assert rec["straight"]["print_time_s"] == price.straight.seconds
        assert "prime line not counted" in rec["assumptions"]
    assert high.time_ratio > low.time_ratio and high.mass_ratio > low.mass_ratio
    assert low.straight == high.straight
