"""The waved-strand coupon: its mesh is watertight with the closed-form volume, its direct
G-code lays that volume and passes the checker, PrusaSlicer slices it; `calibrate` of a
synthetic export made from the beam model with a known law scale gives that scale back (noise
free and noisy), notices a coupon whose wave is not the designed one, refuses bad sidecars
and writes the scaled law into the profile the verification then reads; `testpieces` of a
waved design writes the coupon, its prediction and its sidecar."""

from __future__ import annotations

import dataclasses
import json
import subprocess
import sys

import numpy as np
import pytest
from conftest import (
    reference_design_1_40,
    require_shared,
    slice_check_piece,
    write_test_pieces,
)
from test_calibrate_files import noisy_breaking_exports, write_export

from printgen.calibrate.pipeline import calibrate
from printgen.calibrate.waved import WaveCalibration, WaveModel, read_wave
from printgen.errors import CalibrationError, GeometryError, PrintgenError
from printgen.inputs.materials import load_material
from printgen.inputs.printers import load_print_style, load_printer
from printgen.parts.gcode.couponpath import coupon_toolpath, coupon_volume_budget
from printgen.parts.gcode.writer import gcode_text
from printgen.parts.geometry.wave import wave_length
from printgen.parts.geometry.wavecoupon import (
    analytic_coupon_volume,
    coupon_solid,
    waved_coupon_for,
)
from printgen.scaling.record import Section, Wave

VOLUME_TOL = 0.02  # the brief: the coupon's volume within 2 % of the analytic one, and its
# G-code's within 2 % of the STL's (the checker's --volume-tol)
STRANDS_VS_ANALYTIC = 2e-3  # the strands' share of the mesh volume vs width x arc x thickness:
# the polylines sit within 0.01 mm of the waves (measured 1.5e-4 on the 1:40 coupon)
DEPOSIT_REL = 1e-9  # the toolpath's volume is its budget's deposit: the same moves summed
SCALE_RTOL = {0.0: 1e-3, 0.005: 0.01, 0.02: 0.02}  # recovered law scale, by the noise's SD
# as a fraction of the largest force: noise free, the fit reads the model back to its
# interpolation (1e-3); a least-squares scale over 600 points errs by about sd / sqrt(600) of
# the force, far within 1 % and 2 %
PANEL_LINEAR_RTOL = 1e-6  # a scaled law's panel vs the scaled panel: the solver's equilibrium
# tolerance (the positions do not move with the scale, the forces follow it exactly)
KNEE_RTOL = 0.05  # measured vs predicted bilinear knee on data made from the model, noisy
SCALE = 1.3  # the known scale of the material law the synthetic exports are made with
N_POINTS = 600
SLICE_TIMEOUT_S = 300


WAVE = Wave(1.5, 1)  # the top of the 1.0-1.5 mm range asked of the 1:40 net


def _waved(wave: Wave = WAVE, two_beads: bool = False):
    d = reference_design_1_40()
    net = dataclasses.replace(d.net, wave=wave)
    if two_beads:  # the 1:60 pick's strand: TPU 85A, 2 beads x 5 layers
        net = dataclasses.replace(net, material="tpu-85a",
                                  strand=Section(0.6, 2, (0.35, 0.3, 0.3, 0.3, 0.3)))
    return dataclasses.replace(d, net=net)


COUPONS = {"tpe-1-bead": lambda: _waved(), "tpu-2-beads-3-half-waves":
           lambda: _waved(Wave(0.5, 3), two_beads=True)}


# ----------------------------------------------------------------------------- geometry
@pytest.mark.parametrize("name", COUPONS)
def test_coupon_mesh_is_watertight_with_the_closed_form_volume(name):
    c = waved_coupon_for(COUPONS[name]())
    mesh = coupon_solid(c)
    assert mesh.is_watertight and mesh.is_winding_consistent
    exact = analytic_coupon_volume(c)
    assert mesh.volume == pytest.approx(exact, rel=VOLUME_TOL)
    # the strands alone (the tabs are boxes): the test that reads the waves
    tabs = 2 * c.tab_mm * c.width_mm * c.section.thickness_mm
    strands = c.strands * c.section.area_mm2 * wave_length(c.chord_mm, c.wave)
    assert mesh.volume - tabs == pytest.approx(strands, rel=STRANDS_VS_ANALYTIC)


def test_coupon_is_the_nets_strand_between_tabs_and_refuses_a_straight_design():
    d = _waved()
    c = waved_coupon_for(d)
    assert c.chord_mm == pytest.approx(np.hypot(20.6 / 2, 9.4 / 2))  # the diamond's strand
    assert c.wave == d.net.wave and c.section == d.net.strand
    assert c.strands % 2 == 0  # mirrored pairs: no net moment on the tabs
    # neighbouring bands never touch: pitch - (2 a + W) is one strand width of gap
    assert c.pitch_mm - (2 * c.wave.amplitude_mm + c.section.width_mm) == pytest.approx(
        c.section.width_mm)
    with pytest.raises(GeometryError, match="straight"):
        waved_coupon_for(reference_design_1_40())
    with pytest.raises(GeometryError, match="amplitude of at most"):
        waved_coupon_for(_waved(Wave(1.0, 5)))  # bends on 0.52 mm < one 0.6 mm bead


@pytest.mark.parametrize("name", COUPONS)
def test_direct_gcode_lays_the_coupon_and_passes_the_checker(name, tmp_path):
    d = COUPONS[name]()
    c = waved_coupon_for(d)
    printer, style = load_printer(d.printer), load_print_style(c.print_style)
    mat = load_material(c.material)
    tp = coupon_toolpath(c, printer, style, mat)
    budget = coupon_volume_budget(c, style.crossing_flow_factor)
    assert tp.volume_mm3 == pytest.approx(budget.deposit_mm3, rel=DEPOSIT_REL)
    mesh = coupon_solid(c)
    assert tp.volume_mm3 == pytest.approx(mesh.volume, rel=VOLUME_TOL)
    script = require_shared("tools/gcode/check_gcode.py")
    gcode, stl = tmp_path / "c.gcode", tmp_path / "c.stl"
    gcode.write_text(gcode_text(tp, printer, mat))
    mesh.export(stl)
    r = subprocess.run(
        [sys.executable, str(script), str(gcode), "--bed", "350x350x300", "--width",
         f"{c.section.bead_width_mm}", "--area-model", "rect", "--layers",
         f"{len(c.section.layer_heights_mm)}", "--min-hotend",
         f"{mat.print.first_layer_nozzle_temperature_deg_c:g}", "--max-flow",
         f"{mat.print.max_volumetric_flow_mm3_per_s:g}", "--stl", str(stl), "--volume-tol",
         f"{VOLUME_TOL}"], capture_output=True, text=True, timeout=SLICE_TIMEOUT_S, check=False)
    assert r.returncode == 0, r.stdout.strip().splitlines()[-1]


# ----------------------------------------------------------------------------- calibrate
LINEAR_E = load_material("petg").modulus()[0]  # Pa: the sidecar's linear law (below) is the
# material's own, so a profile saved from it passes the datasheet check


def _sidecar(path, *, amplitude_mm=1.5, strands=4, knees=(), slopes_mpa=(LINEAR_E / 1e6,),
             wave=True):
    chord = float(np.hypot(10.3, 4.7))
    lines = ['kind = "waved"', f"width_mm = {strands * 0.6}", "thickness_mm = 0.95",
             f"gauge_length_mm = {chord}", f"grip_distance_mm = {chord}"]
    if wave:
        lines += ["[wave]", f"chord_mm = {chord}", f"amplitude_mm = {amplitude_mm}",
                  "half_waves = 1", f"strands = {strands}", "strand_width_mm = 0.6",
                  "thickness_mm = 0.95", 'material = "petg"', 'law_source = "test law"',
                  f"stress_knees = {list(knees)}", f"stress_slopes_mpa = {list(slopes_mpa)}"]
    path.write_text("\n".join(lines) + "\n")
    return path


def _exports(tmp_path, model: WaveModel, scale: float, noise: float, n: int = 3,
             seed: int = 36) -> list:
    """Bluehill-like exports of coupons whose law is `scale` x the model's: force from the
    beam model, crosshead displacement over the chord, normal noise of SD `noise` x the
    largest force, then a drop (the break) the fit must leave out."""
    eps = np.linspace(0.0, model.top(), N_POINTS)
    force = scale * model.strands * model.curve().law().force_and_tangent(eps)[0]
    return noisy_breaking_exports(tmp_path, "wave", eps, force, model.chord, noise, n, seed)


@pytest.mark.parametrize("noise", SCALE_RTOL)
def test_synthetic_export_from_the_beam_model_gives_its_law_scale_back(noise, tmp_path):
    side = _sidecar(tmp_path / "wave.toml")
    model = read_wave(side)
    cal = calibrate(_exports(tmp_path, model, SCALE, noise), material="petg-lab",
                    specimen_file=side)
    assert isinstance(cal, WaveCalibration)
    assert cal.scale.mean == pytest.approx(SCALE, rel=SCALE_RTOL[noise])
    assert cal.modulus == pytest.approx(SCALE * LINEAR_E, rel=SCALE_RTOL[noise])
    measured, predicted = cal.knees()
    assert measured.mean == pytest.approx(predicted.mean, rel=KNEE_RTOL)
    assert not [w for w in cal.warnings if "knee" in w]
    said_measured, said_assumed = cal.assumptions()
    assert "scale" in said_measured and "wave as designed" in said_assumed


def test_a_nonlinear_law_is_scaled_whole(tmp_path):
    """A softening law (a knee inside the fitted range): the force is still linear in the
    law's scale, so the scale comes back exactly."""
    side = _sidecar(tmp_path / "wave.toml", knees=(0.1,), slopes_mpa=(14.0, 3.0))
    model = read_wave(side)
    cal = calibrate(_exports(tmp_path, model, SCALE, 0.0), material="petg-lab",
                    specimen_file=side)
    assert cal.scale.mean == pytest.approx(SCALE, rel=SCALE_RTOL[0.0])


def test_an_extensometer_strain_is_used_and_its_span_questioned(tmp_path):
    side = _sidecar(tmp_path / "wave.toml")
    model = read_wave(side)
    eps = np.linspace(0.0, model.top(), N_POINTS)
    force = SCALE * model.predict(eps)
    export = write_export(tmp_path / "ext", {"time": np.arange(eps.size) * 0.1, "force": force,
                                             "strain": eps}, "bluehill_quoted")
    cal = calibrate([export], material="petg-lab", specimen_file=side)
    assert cal.scale.mean == pytest.approx(SCALE, rel=SCALE_RTOL[0.0])
    assert any("extensometer" in w and "--strain-source crosshead" in w for w in cal.warnings)


def test_a_coupon_printed_with_another_wave_is_flagged_by_its_knee(tmp_path):
    """Exports of a wave 30 % deeper than the sidecar's: its knee (about the excess length,
    ~ a^2) falls far later than the model's, and calibrate says so."""
    side = _sidecar(tmp_path / "wave.toml")
    deeper = read_wave(_sidecar(tmp_path / "deeper.toml", amplitude_mm=1.95))
    cal = calibrate(_exports(tmp_path, deeper, 1.0, 0.005), material="petg-lab",
                    specimen_file=side)
    measured, predicted = cal.knees()
    assert measured.mean > 1.25 * predicted.mean
    assert any("knee" in w and "not the designed one" in w for w in cal.warnings)


@pytest.mark.parametrize(("kw", "message"), [
    ({"wave": False}, "no \\[wave\\] table"),
    ({"knees": (0.1,)}, "one more slope than knees"),
    ({"slopes_mpa": (-3.0,)}, "every slope > 0"),
    ({"amplitude_mm": 0.0}, "amplitude_mm"),
])
def test_bad_waved_sidecars_are_refused_with_the_fix(kw, message, tmp_path):
    side = _sidecar(tmp_path / "wave.toml", **kw)
    export = write_export(tmp_path / "e", {"time": np.arange(50.0), "force": np.arange(50.0),
                                           "displacement": np.arange(50.0) * 1e-5},
                          "bluehill_quoted")
    with pytest.raises(PrintgenError, match=message):  # CalibrationError or InputError
        calibrate([export], material="petg-lab", specimen_file=side)


def test_too_few_points_in_the_model_range_is_an_error(tmp_path):
    side = _sidecar(tmp_path / "wave.toml")
    export = write_export(tmp_path / "e", {"time": np.arange(10.0), "force": np.arange(10.0),
                                           "displacement": np.arange(10.0) * 1e-5},
                          "bluehill_quoted")
    with pytest.raises(PrintgenError, match="loading points"):
        calibrate([export], material="petg-lab", specimen_file=side)


@pytest.mark.slow
def test_cli_saves_the_scaled_law_and_refuses_bad_input_with_exit_2(tmp_path, capsys):
    from printgen.cli import main

    side = _sidecar(tmp_path / "wave.toml")
    exports = [str(p) for p in _exports(tmp_path, read_wave(side), SCALE, 0.005)]
    out = tmp_path / "profiles"
    assert main(["calibrate", *exports, "--material", "petg-lab", "--inherits", "petg",
                 "--specimen", str(side), "--out", str(out), "--plot", str(tmp_path / "plot"),
                 "--json"]) == 0
    rec = json.loads(capsys.readouterr().out)
    assert rec["law_scale"]["mean"] == pytest.approx(SCALE, rel=SCALE_RTOL[0.005])
    assert (tmp_path / "plot" / "petg-lab.png").stat().st_size > 0
    text = (out / "materials" / "petg-lab.toml").read_text()
    assert "beam model" in text and "assumed" in text
    # wrong parent, missing [wave]: exit 2, nothing written
    assert main(["calibrate", *exports, "--material", "petg-lab2", "--inherits", "tpe",
                 "--specimen", str(side), "--out", str(out)]) == 2
    assert "the waved coupon's fit scales" in capsys.readouterr().err  # names the piece
    bad = _sidecar(tmp_path / "bad.toml", wave=False)
    assert main(["calibrate", *exports, "--material", "petg-lab3", "--inherits", "petg",
                 "--specimen", str(bad), "--out", str(out)]) == 2
    assert sorted(p.name for p in (out / "materials").iterdir()) == ["petg-lab.toml"]
    assert "error" in capsys.readouterr().err


@pytest.mark.slow
def test_saved_law_is_what_the_verification_reads(tmp_path, monkeypatch):
    """The fit of a waved TPE coupon writes TPE's measured panel law with its kappas x s; the
    design's waved strands, read from that profile as the scene reads it, pull s times
    harder at every strain: the measured law reaches the verification."""
    from printgen.calibrate.profile_writer import write_profile
    from printgen.run.wavepieces import wave_prediction

    d = _waved()
    curve, _, _ = wave_prediction(d)
    law = curve.strand.stress
    side = _sidecar(tmp_path / "wave.toml", knees=law.knees,
                    slopes_mpa=tuple(v / 1e6 for v in law.slopes))
    side.write_text(side.read_text().replace('material = "petg"', 'material = "tpe"'))
    cal = calibrate(_exports(tmp_path, read_wave(side), SCALE, 0.0), material="tpe-lab",
                    specimen_file=side)
    write_profile(cal, name="tpe-lab", out=tmp_path / "p", inherits="tpe")
    monkeypatch.setenv("PRINTGEN_PROFILES", str(tmp_path / "p"))
    lab = dataclasses.replace(d, net=dataclasses.replace(d.net, material="tpe-lab"))
    after, _, how = wave_prediction(lab)
    assert "panel law" in how
    e = np.linspace(0.01, 0.25, 7)
    np.testing.assert_allclose(after.law().force_and_tangent(e)[0],
                               SCALE * curve.law().force_and_tangent(e)[0],
                               rtol=SCALE_RTOL[0.0])


def test_a_waved_panel_is_linear_in_the_law_scale_and_calibrates_back(tmp_path):
    """The square waved net's simulated free panel (not a mechanism) with its strands' law x
    s carries s x the force at every strain (the module's claim); an export of that scaled
    panel, read with the panel's waved sidecar, gives s back."""
    from types import SimpleNamespace

    from printgen.run.wavepieces import wave_panel_sidecar
    from printgen.scaling.panel_test import simulate
    from printgen.scene.panel import curved_panel, lattice_size
    from printgen.units import MM

    d = _waved()
    d = dataclasses.replace(d, net=dataclasses.replace(d.net, pattern="square", mesh_x_mm=12.0,
                                                       mesh_y_mm=12.0))
    dp = curved_panel(d, "short", WAVE.amplitude_mm, WAVE.half_waves, "free")
    assert dp.curve.hold_share < 0.5
    scaled = simulate(dp.law.scaled(SCALE), dp.test, dp.curve.strains)
    np.testing.assert_allclose(scaled.force_per_width, SCALE * dp.curve.force_per_width,
                               rtol=PANEL_LINEAR_RTOL)
    length, width = lattice_size(dp.test)
    wave_panel_sidecar(tmp_path, d, dp, SimpleNamespace(width_mm=width / MM,
                                                        length_mm=length / MM))
    side = tmp_path / "panel.specimen.toml"
    model = read_wave(side)
    assert model.panel and model.panel_width == pytest.approx(width)
    eps = np.linspace(0.0, model.top(), N_POINTS)
    force = np.interp(eps, (0.0, *scaled.strains), (0.0, *scaled.force_per_width)) * width
    export = write_export(tmp_path / "panel-1", {"time": np.arange(eps.size) * 0.1,
                                                 "force": force, "displacement": eps * length},
                          "bluehill_quoted")
    cal = calibrate([export], material="tpe-lab", specimen_file=side)
    assert cal.scale.mean == pytest.approx(SCALE, rel=SCALE_RTOL[0.0])
    assert "simulated free test" in cal.assumptions()[1]


# ----------------------------------------------------------------------------- testpieces
@pytest.fixture(scope="module")
def pieces(tmp_path_factory):
    return write_test_pieces(_waved(), tmp_path_factory.mktemp("waved-pieces"))


@pytest.mark.slow
def test_testpieces_of_a_waved_design_writes_the_coupon_and_its_prediction(pieces):
    d, rec, out = pieces
    names = {p.name for p in out.iterdir()}
    assert {"wave-coupon.stl", "wave-coupon.3mf", "wave-coupon.prusa.ini",
            "wave-coupon.gcode", "wave-coupon.specimen.toml",
            "wave-coupon-expected.csv"} <= names
    assert {"coupon.stl", "panel.stl"} <= names  # the straight coupon and the waved panel too
    listed = set(json.loads((out / "manifest.json").read_text())["files"])
    assert names - {"manifest.json"} <= listed
    w = rec["wave_coupon"]
    assert abs(w["readback_vs_stl"]) < VOLUME_TOL
    rows = np.genfromtxt(out / "wave-coupon-expected.csv", delimiter=",", names=True)
    model = read_wave(out / "wave-coupon.specimen.toml")
    np.testing.assert_allclose(rows["force_n"], model.strands * model.curve().law()
                               .force_and_tangent(rows["chord_strain"])[0], rtol=1e-5)
    # soft while it unbends, then nearly the straight strand's stiffness
    assert rows["strand_force_n"][0] < 0.5 * rows["straight_strand_force_n"][0]
    readme = (out / "README.md").read_text()
    assert "Print first: the straight coupon" in readme and "wave-coupon-expected.csv" in readme
    assert "curved strands" in rec["panel"]["strands"]


@pytest.mark.slow
def test_the_diamond_waved_panel_is_a_mechanism_and_calibrate_says_what_to_do(pieces, tmp_path):
    _, rec, out = pieces
    assert rec["panel"]["expected_curve"]["free_hold_share"] > 0.5
    export = write_export(tmp_path / "e", {"time": np.arange(50.0), "force": np.arange(50.0),
                                           "displacement": np.arange(50.0) * 1e-4},
                          "bluehill_quoted")
    with pytest.raises(CalibrationError, match="mechanism.*waved coupons"):
        calibrate([export], material="tpe-lab", specimen_file=out / "panel.specimen.toml")


@pytest.mark.slow
def test_testpieces_sidecar_calibrates_a_synthetic_export_back(pieces, tmp_path):
    _, _, out = pieces
    side = out / "wave-coupon.specimen.toml"
    cal = calibrate(_exports(tmp_path, read_wave(side), SCALE, 0.005), material="tpe-lab",
                    specimen_file=side)
    assert cal.scale.mean == pytest.approx(SCALE, rel=SCALE_RTOL[0.005])


@pytest.mark.slow
def test_prusaslicer_slices_the_waved_coupon_and_the_checker_passes_it(pieces, tmp_path):
    d, _, out = pieces
    ini = dict(line.split(" = ", 1) for line in
               (out / "wave-coupon.prusa.ini").read_text().splitlines() if " = " in line)
    # the tabs (most of the coupon's extrusion) are laid at the .ini's extrusion width
    slice_check_piece(d, out, "wave-coupon", tmp_path, width=ini["extrusion_width"])

