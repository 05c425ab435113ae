"""`printgen testpieces` of a square-mesh design (straight and waved strands): the square test
panel is no mechanism (its loaded strands carry the strand law, analytic), is sized as argued,
its meshes are watertight, its direct G-code passes the checker and PrusaSlicer slices it; an
export made from its simulated test with a known law scale calibrates back to that scale, and
the saved profile gives the verification's strand law times that scale."""

from __future__ import annotations

import dataclasses
import json
import subprocess
import sys

import numpy as np
import pytest
from conftest import (
    piece_files,
    reference_design_1_40,
    require_shared,
    slice_check_piece,
    write_test_pieces,
)
from test_calibrate_files import noisy_breaking_exports, write_export

from printgen.calibrate.pipeline import calibrate
from printgen.calibrate.specimen import read_sidecar
from printgen.calibrate.waved import WaveCalibration, read_wave
from printgen.inputs.materials import load_material
from printgen.report.jsonout import dumps
from printgen.scaling.record import Wave
from printgen.scene.panel import (
    SQUARE_MIN_MESHES,
    SQUARE_MIN_STRANDS,
    PanelTest,
    lattice_size,
    loaded_strands,
    simulate,
    square_panel_size,
)
from printgen.units import MM

PANEL_RTOL = {"blocked": 1e-6,  # simulated vs analytic panel force: the solver's
              # equilibrium tolerance (PANEL_TOL 1e-9 of the strand force) with margin
              "free": 2e-3}  # ... plus the free solve's hold: every free node tied to its
# rest place at HOLD_RATIO (1e-4) x the strand stiffness, along the load too, which the
# interior rows' ties add to the clamp force (measured 7e-4 on 4 x 9 meshes at 40 %)
HOLD_MAX = 1e-6  # the free square panel's share of clamp force carried by the solver's hold:
# no mechanism (the diamond's free panel is over 0.5)
SCALE = 0.8  # the known scale of the material law the synthetic exports are made with
SCALE_RTOL = {0.0: 1e-3, 0.005: 0.01}  # recovered law scale, by the noise's SD as a fraction
# of the largest force: noise free, the fit reads the prediction back to the interpolation of
# its sampled points (1e-3); a least-squares scale over 600 points errs by about
# sd / sqrt(600) of the force, far within 1 %
LAW_RTOL = 1e-3  # the saved profile's strand law vs SCALE x the assumed one: the profile
# writes 6 significant digits (`profile_writer.SIG`) of a scale recovered to 1e-3
PANEL_VOLUME_TOL = 0.15  # direct panel G-code vs its STL: the panel's (test_testpieces): its
# strand ends meet the plain border at full flow
N_POINTS = 600
CHECK_TIMEOUT_S = 300
MESH_MM = 12.0  # the square mesh of the test designs (the waved panel test's, test_wave_coupon)


def _square(wave: Wave | None = None):
    """The 1:40 reference design's net (TPE, 0.6 x 0.95 mm strands) on a square mesh."""
    d = reference_design_1_40()
    net = dataclasses.replace(d.net, pattern="square", mesh_x_mm=MESH_MM, mesh_y_mm=MESH_MM,
                              wave=wave)
    return dataclasses.replace(d, net=net)


DESIGNS = {"straight": lambda: _square(), "waved": lambda: _square(Wave(1.5, 1))}


# ----------------------------------------------------------------------------- the test
def test_square_panel_is_its_loaded_strands_pulling_the_strand_law():
    """Free or blocked, the simulated square panel's clamp force is its nx + 1 strands along
    the load each at the strand law of the panel strain (analytic), with no hold."""
    from printgen.solver import Law

    law = Law((0.2,), (8.0, 2.0))  # N per unit strain, softening as TPE's
    mesh = MESH_MM * MM
    eps = np.linspace(0.02, 0.4, 8)
    size = square_panel_size(mesh)
    curves = {mode: simulate(law, PanelTest(mesh, mesh, *size, mode, "square"), eps)
              for mode in ("free", "blocked")}
    t = curves["free"].test
    _, simulated = loaded_strands(t)
    width = lattice_size(t)[1]
    expected = simulated * law.force_and_tangent(eps)[0] / width
    for mode, c in curves.items():
        np.testing.assert_allclose(c.force_per_width, expected, rtol=PANEL_RTOL[mode])
    assert curves["free"].hold_share < HOLD_MAX


@pytest.mark.parametrize("mesh_mm", [5.0, 12.0, 20.0, 40.0])
def test_panel_size_holds_the_argued_strands_and_meshes(mesh_mm):
    mesh = mesh_mm * MM
    t = PanelTest(mesh, mesh, *square_panel_size(mesh), "free", "square")
    length, width = lattice_size(t)
    loaded, simulated = loaded_strands(t)
    assert loaded >= SQUARE_MIN_STRANDS and simulated == loaded + 2
    assert round(length / mesh) >= SQUARE_MIN_MESHES
    assert length >= 43 * MM - mesh / 2  # the paper's printed panel, to whole meshes


# ----------------------------------------------------------------------------- the folder
@pytest.fixture(scope="module", params=list(DESIGNS))
def pieces(request, tmp_path_factory):
    return write_test_pieces(DESIGNS[request.param](), tmp_path_factory.mktemp(
        f"square-{request.param}"))


@pytest.mark.slow
def test_folder_holds_the_pieces_the_sidecars_and_the_square_loop(pieces):
    d, rec, out = pieces
    names = {p.name for p in out.iterdir()}
    for piece in ("coupon", "panel"):
        assert piece_files(piece) <= names
    assert ("wave-coupon.stl" in names) == (d.net.wave is not None)
    listed = set(json.loads((out / "manifest.json").read_text())["files"])
    assert names - {"manifest.json"} <= listed
    side = read_sidecar(out / "panel.specimen.toml")
    assert side["kind"] == ("waved" if d.net.wave else "panel")
    g, e = rec["panel"]["geometry"], rec["panel"]["expected_curve"]
    assert g["orientation"] == "strands"
    assert side["width"] == pytest.approx(g["width_mm"] * MM)
    assert side["grip_distance"] == pytest.approx(g["length_mm"] * MM)
    assert e["free_hold_share"] < HOLD_MAX
    assert e["loaded_strands"] >= SQUARE_MIN_STRANDS
    rows = np.genfromtxt(out / "panel-expected.csv", delimiter=",", names=True)
    k, m = e["loaded_strands"], e["simulated_strands"]
    np.testing.assert_allclose(rows["tested_n_per_m"], rows["simulated_n_per_m"] * k / m,
                               rtol=1e-5)  # the CSV's 6 significant digits
    readme = (out / "README.md").read_text()
    assert "strands that run up" in readme and "Cut the two side bars" in readme
    assert "--specimen panel.specimen.toml" in rec["loop"][2]


@pytest.mark.slow
def test_meshes_are_watertight(pieces):
    trimesh = pytest.importorskip("trimesh")
    d, _, out = pieces
    for piece in ("coupon", "panel", *(["wave-coupon"] if d.net.wave else [])):
        mesh = trimesh.load(out / f"{piece}.stl")
        assert mesh.is_watertight and mesh.is_winding_consistent, piece


@pytest.mark.slow
def test_direct_panel_gcode_passes_the_checker(pieces):
    script = require_shared("tools/gcode/check_gcode.py")
    d, rec, out = pieces
    mat = load_material(d.net.material).print
    r = subprocess.run(
        [sys.executable, str(script), str(out / "panel.gcode"), "--bed", "350x350x300",
         "--width", f"{d.net.strand.bead_width_mm}", "--area-model", "rect",
         "--layers", f"{len(d.net.strand.layer_heights_mm)}",
         "--min-hotend", f"{mat.first_layer_nozzle_temperature_deg_c:g}",
         "--max-flow", f"{mat.max_volumetric_flow_mm3_per_s:g}",
         "--stl", str(out / "panel.stl"), "--volume-tol", f"{PANEL_VOLUME_TOL}"],
        capture_output=True, text=True, timeout=CHECK_TIMEOUT_S, check=False)
    assert r.returncode == 0, r.stdout.strip().splitlines()[-1]
    assert abs(rec["panel"]["readback_vs_stl"]) < PANEL_VOLUME_TOL


def _panel_exports(tmp_path, out, scale: float, noise: float, n: int = 3) -> list:
    """Bluehill-like exports of panels whose law is `scale` x the assumed one: force from the
    simulated test's tested column (times the clamp width), crosshead displacement over the
    clamp distance, normal noise of SD `noise` x the largest force, then a drop (the
    break)."""
    model = read_wave(out / "panel.specimen.toml")
    length = read_sidecar(out / "panel.specimen.toml")["grip_distance"]
    eps = np.linspace(0.0, model.top(), N_POINTS)
    force = scale * model.predict(eps) * model.panel_width
    return noisy_breaking_exports(tmp_path, "panel", eps, force, length, noise, n)


@pytest.mark.slow
@pytest.mark.parametrize("noise", SCALE_RTOL)
def test_synthetic_panel_export_calibrates_back_to_its_law_scale(pieces, noise, tmp_path):
    d, rec, out = pieces
    side = out / "panel.specimen.toml"
    cal = calibrate(_panel_exports(tmp_path, out, SCALE, noise), material="tpe-lab",
                    specimen_file=side)
    assert isinstance(cal, WaveCalibration) and cal.model.panel
    assert cal.model.straight == (d.net.wave is None)
    assert cal.scale.mean == pytest.approx(SCALE, rel=SCALE_RTOL[noise])
    assert "simulated free test" in cal.assumptions()[0 if cal.model.straight else 1]


@pytest.mark.slow
def test_saved_panel_calibration_feeds_the_scaled_law_to_the_verification(pieces, tmp_path,
                                                                         monkeypatch):
    """The profile written from the panel's fit gives the design's strands (the law the
    verification's scene takes, `model_net_law`) SCALE x the law the prediction assumed."""
    from printgen.calibrate.profile_writer import write_profile
    from printgen.scene.scenes import model_net_law

    d, _, out = pieces
    cal = calibrate(_panel_exports(tmp_path, out, SCALE, 0.0), material="tpe-lab",
                    specimen_file=out / "panel.specimen.toml")
    before = model_net_law(load_material("tpe"), d.net, None)[0]
    write_profile(cal, name="tpe-lab", out=tmp_path / "p", inherits="tpe")
    monkeypatch.setenv("PRINTGEN_PROFILES", str(tmp_path / "p"))
    after = model_net_law(load_material("tpe-lab"), d.net, None)[0]
    e = np.linspace(0.01, 0.5, 9)
    np.testing.assert_allclose(after.force_and_tangent(e)[0],
                               SCALE * before.force_and_tangent(e)[0], rtol=LAW_RTOL)


def test_square_panel_sidecar_refuses_a_bad_prediction(tmp_path):
    from printgen.errors import CalibrationError

    side = tmp_path / "panel.toml"
    side.write_text('kind = "panel"\nwidth_mm = 108\ngrip_distance_mm = 48\n\n[prediction]\n'
                    'material = "tpe"\nstress_knees = []\nstress_slopes_mpa = [14.1]\n'
                    "strands = 8\nstrand_width_mm = 0.6\nthickness_mm = 0.95\nmesh_mm = 12\n"
                    "panel_strains = [0.01]\npanel_n_per_m = [5.0]\n")
    with pytest.raises(CalibrationError, match="panel_strains"):
        read_wave(side)
    export = write_export(tmp_path / "e", {"time": np.arange(50.0), "force": np.arange(50.0),
                                           "displacement": np.arange(50.0) * 1e-4},
                          "bluehill_quoted")
    with pytest.raises(CalibrationError, match="no --kind"):
        calibrate([export], material="tpe-lab", specimen={"kind": "panel"},
                  specimen_file=side)


FAILURE_RTOL = 1e-6  # the last predicted strain's strand stress vs the failure stress: the
# strain is solved in closed form, the panel's force to the solver's tolerance (PANEL_RTOL)


def test_a_stiff_strands_prediction_ends_where_the_strands_reach_their_failure_stress():
    """A PETG square net's panel would be predicted to the 10 % of a linear law, far past its
    break: the prediction stops where the strand reaches the failure stress, and says so."""
    from printgen.run.squarepieces import square_panel
    from printgen.scaling.section import area_m2

    d = _square()
    d = dataclasses.replace(d, net=dataclasses.replace(d.net, material="petg"))
    dp = square_panel(d, "short")
    mat = load_material("petg")
    _, simulated = loaded_strands(dp.test)
    width = lattice_size(dp.test)[1]
    stress = dp.curve.force_per_width[-1] * width / simulated / area_m2(d.net.strand)
    assert stress == pytest.approx(mat.failure_stress()[0], rel=PANEL_RTOL["free"])
    assert dp.curve.strains[-1] < 0.1 and "failure stress" in dp.strands
    assert dp.law.force_and_tangent(dp.curve.strains[-1:])[0][0] == pytest.approx(
        mat.failure_stress()[0] * area_m2(d.net.strand), rel=FAILURE_RTOL)


@pytest.mark.slow
def test_cli_writes_a_square_designs_pieces(tmp_path, capsys):
    from printgen.cli import main

    path = tmp_path / "design.json"
    path.write_text(dumps(_square().to_dict()))
    assert main(["testpieces", str(path), "--out", str(tmp_path / "ok"), "--json"]) == 0
    rec = json.loads(capsys.readouterr().out)
    assert rec["panel"]["geometry"]["orientation"] == "strands"
    assert main(["testpieces", str(path), "--out", str(tmp_path / "table")]) == 0
    assert "panel.specimen.toml" in capsys.readouterr().out


@pytest.mark.slow
def test_prusaslicer_slices_the_square_panel_and_the_checker_passes_it(pieces, tmp_path):
    d, _, out = pieces
    slice_check_piece(d, out, "panel", tmp_path)
