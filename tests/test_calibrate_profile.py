"""A calibrated profile is written, loaded by load_material and reported as measured; the CLI."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose
from test_calibrate_files import write_export
from test_calibrate_laws import AREA, GRIP, N_POINTS, STRAIN_MAX, THICK, WIDTH, _write

from printgen.calibrate.pipeline import calibrate
from printgen.calibrate.profile_writer import write_profile
from printgen.calibrate.sample import FitOptions
from printgen.calibrate.specimen import find_sidecar, read_sidecar
from printgen.cli import main
from printgen.errors import CalibrationError
from printgen.inputs.materials import load_material

FIT_RTOL = 0.005  # fitted values vs the law that generated the files (issue: 0.5 %)
TOML_RTOL = 1e-5  # values are written with 6 significant digits
EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "calibration"
MODULI = np.array([1.28, 1.30, 1.33, 1.29, 1.31]) * 1e9  # Pa, five printed PETG cables


@pytest.fixture
def cable_files(tmp_path):
    eps = np.linspace(0, STRAIN_MAX, N_POINTS)
    return [_write(tmp_path, f"petg_{i}", eps, e * eps, "semicolon_decimal_comma", seed=20 + i)
            for i, e in enumerate(MODULI)]


def _spec():
    return {"width": WIDTH, "thickness": THICK, "grip_distance": GRIP}


def test_new_profile_loads_as_measured(tmp_path, cable_files, monkeypatch):
    cal = calibrate(cable_files, material="petg-lab", specimen=_spec(),
                    conditions="printed 7 days before the test, 23 degC")
    out = tmp_path / "profiles"
    path, mat = write_profile(cal, name="petg-lab", out=out, inherits="petg", date="2026-11-24")
    assert path == out / "materials" / "petg-lab.toml"
    monkeypatch.setenv("PRINTGEN_PROFILES", str(out))
    m = load_material("petg-lab")
    e, source = m.modulus()
    assert source == "measured"
    assert_allclose(e, MODULI.mean(), rtol=FIT_RTOL)
    assert_allclose(m.measured_modulus.sd, np.std(MODULI, ddof=1), rtol=FIT_RTOL * 20)
    mm = m.measured_modulus
    assert mm.n_samples == 5 and mm.date == "2026-11-24"
    assert mm.fit_window_percent == (0.05, 0.25) and mm.correction == "none"
    assert [Path(f).name for f in mm.files] == [p.name for p in cable_files]
    assert "printed 7 days" in mm.conditions and "crosshead" in mm.conditions
    assert m.failure_stress()[1] == "measured"
    petg = load_material("petg")  # datasheet and print settings carry over
    assert (m.datasheet_modulus, m.print) == (petg.datasheet_modulus, petg.print)
    assert mat.modulus() == m.modulus()


def test_update_keeps_the_rest_and_refuses_bad_targets(tmp_path, cable_files, monkeypatch):
    cal = calibrate(cable_files, material="petg-lab", specimen=_spec())
    out = tmp_path / "p"
    path, _ = write_profile(cal, name="petg-lab", out=out, inherits="petg")
    path.write_text("density_g_per_cm3 = 1.31\n" + path.read_text())  # a lab's own edit
    two = calibrate(cable_files[:2], material="petg-lab", specimen=_spec())
    write_profile(two, name="petg-lab", out=out)
    data = tomllib.loads(path.read_text())
    assert data["inherits"] == "petg" and data["density_g_per_cm3"] == 1.31
    assert data["name"] == "petg-lab"
    assert data["measured"]["tensile_modulus"]["n_samples"] == 2
    with pytest.raises(CalibrationError, match="cannot inherit itself"):
        write_profile(cal, name="petg", out=out, inherits="petg")
    with pytest.raises(CalibrationError, match="give --inherits"):
        write_profile(cal, name="new-one", out=out)
    monkeypatch.delenv("PRINTGEN_PROFILES", raising=False)
    with pytest.raises(CalibrationError, match="give --out DIR or set PRINTGEN_PROFILES"):
        write_profile(cal, name="petg-lab")


def test_panel_law_profile_round_trip(tmp_path, monkeypatch):
    k1, k2, knee, length, width = 30e3, 6e3, 0.40, 43e-3, 23e-3
    eps = np.linspace(0, 0.8, N_POINTS)
    paths = []
    for i, scale in enumerate((0.98, 1.0, 1.02, 0.99, 1.01)):
        fw = scale * (k1 * length * eps + (k2 - k1) * length * np.maximum(eps - knee, 0))
        ch = {"force": fw * width, "displacement": eps * length}
        paths.append(write_export(tmp_path / f"panel{i}", ch, "tab_units_row"))
    cal = calibrate(paths, material="tpe-lab", options=FitOptions(window=(0.02, 0.2)),
                    specimen={"kind": "panel", "width": width, "gauge_length": length})
    write_profile(cal, name="tpe-lab", out=tmp_path / "pr", inherits="tpe")
    monkeypatch.setenv("PRINTGEN_PROFILES", str(tmp_path / "pr"))
    law = load_material("tpe-lab").panel_law
    assert_allclose(law.kappas, [k1, k2], rtol=FIT_RTOL)
    assert_allclose(law.knee_strains, [knee], rtol=FIT_RTOL)
    assert_allclose([law.panel_length, law.panel_width], [length, width], rtol=TOML_RTOL)
    assert_allclose(law.force_per_width(0.6), k1 * length * 0.4 + k2 * length * 0.2,
                    rtol=FIT_RTOL)


@pytest.mark.slow
def test_cli_end_to_end(tmp_path, cable_files, capsys, monkeypatch):
    out = tmp_path / "prof"
    args = ["calibrate", *map(str, cable_files), "--material", "petg-lab", "--width-mm", "2",
            "--thickness-mm", "1", "--grip-distance-mm", "50", "--out", str(out),
            "--inherits", "petg", "--plot", str(tmp_path / "plots"), "--json"]
    assert main(args) == 0
    rec = json.loads(capsys.readouterr().out)
    assert_allclose(rec["modulus_GPa"]["mean"], MODULI.mean() / 1e9, rtol=FIT_RTOL)
    assert rec["written"]["modulus_source"] == "measured: this calibration (5 files)"
    assert rec["written"]["failure_stress_source"] == "measured: this calibration (5 files)"
    assert (tmp_path / "plots" / "petg-lab.png").stat().st_size > 10_000
    monkeypatch.setenv("PRINTGEN_PROFILES", str(out))
    assert main(["profiles", "show", "petg-lab", "--json"]) == 0
    assert "measured" in capsys.readouterr().out
    assert main(["calibrate", *map(str, cable_files), "--material", "x", "--width-mm", "2",
                 "--thickness-mm", "1", "--grip-distance-mm", "50"]) == 0
    assert "modulus" in capsys.readouterr().out


def test_a_materials_link_is_not_written_through(tmp_path, cable_files):
    cal = calibrate(cable_files, material="petg-lab", specimen=_spec())
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (tmp_path / "root").mkdir()
    (tmp_path / "root" / "materials").symlink_to(elsewhere)
    with pytest.raises(CalibrationError, match="materials is a symbolic link"):
        write_profile(cal, name="petg-lab", out=tmp_path / "root", inherits="petg")
    assert list(elsewhere.iterdir()) == []


def test_forces_in_kilonewtons_read_as_newtons_write_nothing(tmp_path):
    eps = np.linspace(0, STRAIN_MAX, N_POINTS)
    files = [_write(tmp_path, f"kn_{i}", eps, e * eps / 1000, "semicolon_decimal_comma",
                    seed=40 + i) for i, e in enumerate(MODULI)]  # kN values, labelled N
    cal = calibrate(files, material="petg-lab", specimen=_spec())
    out = tmp_path / "profiles"
    with pytest.raises(CalibrationError, match=r"modulus 0\.00\d+ GPa is 0\.000\d+ x the "
                                               r"datasheet's 2\.59 GPa.*--unit force=kN"):
        write_profile(cal, name="petg-lab", out=out, inherits="petg")
    assert not (out / "materials" / "petg-lab.toml").exists()


@pytest.mark.parametrize("extra, message", [
    (["--window", "0.25"], "--window '0.25': expected 2 numbers"),
    (["--machine-stiffness", "-3"], "machine stiffness -3 N/mm must be > 0"),
    (["--window", "0.3,0.2"], "fit window"),
    (["--date", "2025-13-45", "--save"], "--date '2025-13-45' is not a calendar day"),
    (["--width-mm", "0"], "--width-mm 0: a specimen dimension must be a positive number of mm"),
    (["--area-mm2", "nan"], "--area-mm2 nan: a specimen dimension must be a positive"),
    (["--date", "2999-01-01", "--save"], "--date 2999-01-01 is after"),
    ([], "needs the grip distance"),
])
def test_cli_bad_input_exits_2(tmp_path, cable_files, capsys, extra, message):
    args = ["calibrate", str(cable_files[0]), "--material", "x", "--width-mm", "2",
            "--thickness-mm", "1"]
    if message != "needs the grip distance":
        args += ["--grip-distance-mm", "50"]
    assert main([*args, *extra]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1, err  # one line, no numpy warnings


def test_sidecar_gives_dimensions_and_columns(tmp_path):
    """A lab file with German headers and no units: the sidecar names columns and units."""
    eps = np.linspace(0, STRAIN_MAX, N_POINTS)
    force = 1.3e9 * eps * AREA
    p = tmp_path / "probe_1.CSV"
    rows = [f"{f:.6f};{d:.6f}".replace(".", ",") for f, d in zip(force, eps * GRIP * 1e3,
                                                                 strict=True)]
    p.write_text("Kanal A;Kanal B\n" + "\n".join(rows) + "\n")
    (tmp_path / "probe_1.toml").write_text(
        (EXAMPLES / "lab_tester_cable.toml").read_text())
    assert find_sidecar(p) == tmp_path / "probe_1.toml"
    cal = calibrate([p], material="petg-lab")
    assert cal.samples[0].specimen.sources["width"].startswith("sidecar")
    assert_allclose(cal.modulus.mean, 1.3e9, rtol=FIT_RTOL)


@pytest.mark.parametrize("name", ["lab_tester_cable.toml", "net_panel.toml"])
def test_example_sidecars_are_valid(name):
    side = read_sidecar(EXAMPLES / name)
    assert side["width"] > 0
