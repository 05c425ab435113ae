"""Issue 20: one budget applied before any work (verify --design's size, make's cables, the
materials weighed, calibrate's rows, design's workers) and the results that were silently
wrong (tensile rows out of time order, an all-zero measured test, bad fit options), plus the
files' mode. Each is refused at the input stage: no solve, no file written."""

from __future__ import annotations

import dataclasses
import json
import os
import stat
import zipfile

import numpy as np
import pytest
from conftest import reference_design_1_40
from proto_files import REALISTIC
from test_calibrate_files import write_export

import printgen.run.verify as verify_mod
from printgen.calibrate import reader
from printgen.calibrate.reader import read_export
from printgen.calibrate.sample import FitOptions
from printgen.cli import main
from printgen.errors import CalibrationError, InputError
from printgen.executor.start import cores
from printgen.inputs.materials import MAX_MATERIALS, material_names
from printgen.inputs.prototype import load_prototype
from printgen.outputs import write_bytes
from printgen.run.budget import CABLE_PART_S, Work, estimate
from printgen.verification.measured import read_measured


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    _, err = capsys.readouterr()
    assert "Traceback" not in err and err.count("\n") == 1, err
    return code, err.strip()


@pytest.mark.slow
def test_verify_design_is_estimated_before_any_solve(capsys, tmp_path, monkeypatch):
    """A 1 mm mesh over the 1:40 net (~60 000 nodes) is refused with the estimate, not solved
    for minutes (a 3 mm mesh ran > 100 s, 0.01 mm ran out of memory)."""
    def no_solve(*a, **k):
        raise AssertionError("verify solved a net the budget should have refused")

    monkeypatch.setattr(verify_mod, "verify_with_band", no_solve)
    d = dataclasses.replace(reference_design_1_40(), printer="generic-350")
    d = dataclasses.replace(d, net=dataclasses.replace(d.net, mesh_x_mm=1.0, mesh_y_mm=1.0))
    design = tmp_path / "design.json"
    design.write_text(json.dumps(d.to_dict()))
    code, err = run(capsys, "verify", REALISTIC, "-s", 40, "--design", design,
                    "--out", tmp_path / "v")
    assert code == 2 and "this run is too big" in err and "model 6" in err, err
    assert "--time-limit" in err and not (tmp_path / "v").exists()


def test_the_fit_of_a_measured_test_counts_in_the_estimate():
    p, d = load_prototype(REALISTIC), reference_design_1_40()
    plain = estimate(p, d, cores=2, work=Work(parts=False)).seconds
    fitted = estimate(p, d, cores=2, work=Work(parts=False, fit=True)).seconds
    assert fitted > plain > 0


def test_make_estimate_counts_every_cable():
    p, d = load_prototype(REALISTIC), reference_design_1_40()
    two = dataclasses.replace(d, cables=d.cables[:2])
    full, fewer = estimate(p, d, cores=2), estimate(p, two, cores=2)
    assert full.parts_s - fewer.parts_s == pytest.approx(2 * CABLE_PART_S)  # exact sum
    assert full.seconds >= fewer.seconds  # the parts may run beside a longer verification


def test_materials_are_capped_and_deduplicated(capsys):
    assert material_names(("tpe", "tpe", "petg")) == ("tpe", "petg")
    names = tuple(f"m{i}" for i in range(MAX_MATERIALS + 1))
    with pytest.raises(InputError, match=f"at most {MAX_MATERIALS}"):
        material_names(names)
    code, err = run(capsys, "select", REALISTIC, "-s", 40, "--materials", *names)
    assert code == 2 and f"{MAX_MATERIALS + 1} materials to weigh" in err


def test_design_workers_limited_to_the_cores(capsys, tmp_path):
    code, err = run(capsys, "design", REALISTIC, "-s", 40, "--workers", cores() + 10,
                    "--objective", "stiffness", "--out", tmp_path / "d")
    assert code == 2 and f"must be from 1 to {cores()}" in err
    assert not (tmp_path / "d").exists()


def _tensile(tmp_path, time: np.ndarray):
    force = np.linspace(0.0, 100.0, time.size)
    return write_export(tmp_path / "t", {"time": time, "force": force,
                                         "displacement": force * 1e-6}, "comma")


def test_rows_out_of_time_order_are_refused(tmp_path):
    t = np.arange(20) * 0.1
    t[[5, 12]] = t[[12, 5]]  # a spreadsheet sort gone wrong
    with pytest.raises(CalibrationError, match=r"line \d+: time 0.6 s is before the line above "
                                               r"\(1.2 s\); 2 rows go back in time"):
        read_export(_tensile(tmp_path, t))
    read_export(_tensile(tmp_path, np.repeat(np.arange(10) * 0.1, 2)))  # equal times are fine


def test_exports_are_capped_in_rows_and_unpacked_size(tmp_path, monkeypatch):
    monkeypatch.setattr(reader, "MAX_ROWS", 50)
    path = _tensile(tmp_path, np.arange(60) * 0.1)
    with pytest.raises(CalibrationError, match="more than 50"):
        read_export(path)
    monkeypatch.setattr(reader, "EXPORT_LIMIT_BYTES", 1 << 10)
    bomb = tmp_path / "bomb.zip"
    with zipfile.ZipFile(bomb, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("rows.csv", "t,f\n" + "0,0\n" * 10_000)  # 40 KB unpacked, ~200 B packed
    with pytest.raises(CalibrationError, match="unpacks to more than"):
        read_export(bomb)


@pytest.mark.parametrize("argv, message", [
    (["--secant", "nan,-1"], "--secant strain nan % must be a positive strain"),
    (["--secant", "0.5,-1"], "--secant strain -1 % must be a positive strain"),
    (["--preload", "-1"], "--preload -1 N must be a positive force"),
    (["--preload", "nan"], "--preload nan N must be a positive force"),
])
def test_fit_options_that_would_fit_silently_wrong(capsys, tmp_path, argv, message):
    code, err = run(capsys, "calibrate", tmp_path / "unread.csv", "--material", "x", *argv)
    assert code == 2 and message in err, err
    with pytest.raises(CalibrationError):
        FitOptions(preload=0.0)


def test_an_all_zero_measured_test_is_refused(tmp_path):
    p = tmp_path / "zero.csv"
    p.write_text("h_over_hb,deflection_over_width\n0,0\n0.5,0\n1.0,0\n")
    with pytest.raises(InputError, match="holds only zeros: nothing to compare or fit"):
        read_measured(p)
    p.write_text("h_over_hb,deflection_over_width\n0,0.01\n0,0.02\n")
    with pytest.raises(InputError, match="never loaded"):
        read_measured(p)


def test_files_are_written_with_the_umask_mode(tmp_path):
    old = os.umask(0o022)
    try:
        path = write_bytes(tmp_path / "profile.toml", b"x = 1\n")
    finally:
        os.umask(old)
    assert stat.S_IMODE(path.stat().st_mode) == 0o644
