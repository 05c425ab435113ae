"""`printgen testpieces`: the coupon and the panel are printable (PrusaSlicer slices them and
the checker passes both slicer and direct G-code), their sidecars are what `calibrate` reads,
and a synthetic tester export of the coupon calibrates back to its modulus."""

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
)
from test_calibrate_files import write_export

from printgen.calibrate.pipeline import calibrate
from printgen.calibrate.specimen import read_sidecar
from printgen.errors import GeometryError
from printgen.inputs.materials import load_material
from printgen.report.jsonout import dumps
from printgen.run.testpieces import RECORD
from printgen.run.testpieces import testpieces as write_pieces
from printgen.scaling.record import Section

MODULUS_RTOL = 0.01  # the issue: a generated export of the coupon calibrates back within 1 %
COUPON_VOLUME_TOL = 0.02  # direct coupon G-code vs its STL: as the net's (test_gcode)
# The panel has no loops, so its strands end in the plain border at full flow: over the
# strand-frame junctions (all in the clamps or in the side bars that are cut) it lays
# +5..7 % more than the STL; the checker's own default tolerance then applies.
PANEL_VOLUME_TOL = 0.15
SLICE_TIMEOUT_S = 300
N_POINTS = 1200
STRAIN_MAX = 0.02  # linear law up to 2 % strain, then a drop the fit must ignore


def _two_bead_tpu():
    """The 1:40 reference design with the 1:60 pick's strand: TPU 85A, 2 beads x 5 layers."""
    d = reference_design_1_40()
    net = dataclasses.replace(d.net, material="tpu-85a",
                              strand=Section(0.6, 2, (0.35, 0.3, 0.3, 0.3, 0.3)))
    return dataclasses.replace(d, net=net)


@pytest.fixture(scope="module", params=["tpe-1-bead", "tpu-2-beads"])
def pieces(request, tmp_path_factory):
    d = reference_design_1_40() if request.param == "tpe-1-bead" else _two_bead_tpu()
    root = tmp_path_factory.mktemp(request.param)
    path = root / "design.json"
    path.write_text(dumps(d.to_dict()))
    out = root / "pieces"
    return d, write_pieces(path, out), out


@pytest.mark.slow
def test_folder_holds_every_piece_its_sidecars_and_the_loop(pieces):
    d, rec, out = pieces
    names = {p.name for p in out.iterdir()}
    for piece in ("coupon", "panel"):
        assert piece_files(piece) <= names
    assert {"panel-expected.csv", "README.md", RECORD, "manifest.json"} <= names
    listed = set(json.loads((out / "manifest.json").read_text())["files"])
    assert names - {"manifest.json"} <= listed
    coupon = read_sidecar(out / "coupon.specimen.toml")
    assert coupon["kind"] == "cable"
    assert coupon["width"] == pytest.approx(d.net.strand.width_mm * 1e-3)
    assert coupon["thickness"] == pytest.approx(d.net.strand.thickness_mm * 1e-3)
    panel = read_sidecar(out / "panel.specimen.toml")
    assert panel["kind"] == "panel"
    g = rec["panel"]["geometry"]
    assert panel["gauge_length"] == pytest.approx(g["length_mm"] * 1e-3)
    readme = (out / "README.md").read_text()
    assert "calibrate" in readme and "print the barrier" in readme
    mat = load_material(d.net.material)
    datasheet = mat.panel_law is None and mat.modulus()[1] == "datasheet"  # tpu-85a, not tpe
    assert ("rests on datasheet values" in readme) == datasheet


def test_expected_panel_curve_lies_between_free_and_blocked(pieces):
    _, _, out = pieces
    rows = np.genfromtxt(out / "panel-expected.csv", delimiter=",", names=True)
    assert np.all(np.diff(rows["strain"]) > 0)
    assert np.all(rows["blocked_n_per_m"] > 0)
    # the free panel (a mechanism held by the solver) carries less than the blocked one
    assert np.all(rows["free_n_per_m"] < rows["blocked_n_per_m"])


def _checker(path, *args):
    script = require_shared("tools/gcode/check_gcode.py")
    r = subprocess.run([sys.executable, str(script), str(path), *args], capture_output=True,
                       text=True, timeout=SLICE_TIMEOUT_S, check=False)
    return r.returncode, r.stdout.strip().splitlines()[-1]


@pytest.mark.parametrize("piece", ["coupon", "panel"])
def test_direct_gcode_passes_the_checker(pieces, piece):
    d, rec, out = pieces
    mat = load_material(d.net.material).print
    tol = COUPON_VOLUME_TOL if piece == "coupon" else PANEL_VOLUME_TOL
    rc, summary = _checker(
        out / f"{piece}.gcode", "--bed", "350x350x300", "--width",
        f"{d.net.strand.bead_width_mm}", "--area-model", "rect",
        "--layers", f"{len(d.net.strand.layer_heights_mm)}",
        "--min-hotend", f"{mat.first_layer_nozzle_temperature_deg_c:g}",
        "--max-flow", f"{mat.max_volumetric_flow_mm3_per_s:g}",
        "--stl", str(out / f"{piece}.stl"), "--volume-tol", f"{tol}")
    assert rc == 0, summary
    assert abs(rec[piece]["readback_vs_stl"]) < tol


@pytest.mark.parametrize("piece", ["coupon", "panel"])
def test_prusaslicer_slices_the_piece_and_the_checker_passes_it(pieces, piece, tmp_path):
    d, _, out = pieces
    slice_check_piece(d, out, piece, tmp_path)


def test_coupon_export_of_a_known_modulus_calibrates_back(pieces, tmp_path):
    """A Bluehill-like export of the coupon (force from its printed section, crosshead
    displacement over its gauge, noise, a failure drop) gives back the modulus, read with
    the coupon's sidecar only."""
    d, rec, out = pieces
    e_true = load_material(d.net.material).modulus()[0]
    g = rec["coupon"]["geometry"]
    area = g["width_mm"] * g["thickness_mm"] * 1e-6
    eps = np.linspace(0.0, STRAIN_MAX, N_POINTS)
    rng = np.random.default_rng(27)
    force = e_true * eps * area
    force = force + 2e-4 * force.max() * rng.standard_normal(eps.size)
    tail = np.linspace(0, 1, 40)[1:]
    eps = np.concatenate([eps, eps[-1] + 0.002 * tail])
    force = np.concatenate([force, force[-1] * (1 - 0.9 * tail)])
    ch = {"time": np.arange(eps.size) * 0.1, "force": force,
          "displacement": eps * g["gauge_length_mm"] * 1e-3}
    p = write_export(tmp_path / "coupon-1", ch, "bluehill_quoted")
    cal = calibrate([p], material="coupon-lab", specimen_file=out / "coupon.specimen.toml")
    assert cal.modulus.mean == pytest.approx(e_true, rel=MODULUS_RTOL)


@pytest.mark.slow
def test_bad_orientation_writes_nothing_for_a_diamond_or_a_square_net(tmp_path):
    d = reference_design_1_40()
    path = tmp_path / "design.json"
    path.write_text(dumps(d.to_dict()))
    with pytest.raises(GeometryError, match="orientation 'diagonal'"):
        write_pieces(path, tmp_path / "a", orientation="diagonal")
    assert not (tmp_path / "a").exists()
    # a square net's panel is pulled along its strands (tests/test_square_pieces.py), but the
    # option is still checked
    sq = dataclasses.replace(d, net=dataclasses.replace(d.net, pattern="square",
                                                        mesh_y_mm=d.net.mesh_x_mm))
    path.write_text(dumps(sq.to_dict()))
    with pytest.raises(GeometryError, match="orientation 'diagonal'"):
        write_pieces(path, tmp_path / "b", orientation="diagonal")
    assert not (tmp_path / "b").exists()


@pytest.mark.slow
def test_cli_writes_the_folder_and_refuses_bad_input_with_exit_2(pieces, tmp_path, capsys):
    from printgen.cli import main

    d, _, _ = pieces
    path = tmp_path / "design.json"
    path.write_text(dumps(d.to_dict()))
    assert main(["testpieces", str(path), "--out", str(tmp_path / "ok"), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["coupon"]["geometry"]["gauge_length_mm"] > 0
    assert main(["testpieces", str(tmp_path / "missing.json"), "--out", str(tmp_path / "x")]) == 2
    assert main(["testpieces", str(path), "--orientation", "diagonal",
                 "--out", str(tmp_path / "y")]) == 2
    assert not (tmp_path / "x").exists() and not (tmp_path / "y").exists()
    assert "error" in capsys.readouterr().err
