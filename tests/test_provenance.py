"""Every run's manifest carries its provenance: the version, the command line, the sha256 of
its inputs and the software environment, so `printgen check` names the code that made it."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from conftest import coarse_simple_file, planned, reference_design_1_40
from proto_files import SIMPLE, write_variant

import printgen
from printgen.cli import main
from printgen.report.jsonout import dumps

pytestmark = pytest.mark.slow


def tiny(folder: Path) -> Path:
    """The simple barrier cut to 2 x 1 m with 0.25 m meshes: seconds for any command."""
    return write_variant(folder, {("barrier", "width_m"): 2.0, ("barrier", "height_m"): 1.0,
                                  ("net", "mesh_x_m"): 0.25, ("net", "mesh_y_m"): 0.25},
                         base=SIMPLE)


def check_provenance(out: Path, command: str, inputs: set[str], capsys) -> None:
    m = json.loads((out / "manifest.json").read_text())
    assert m["printgen_version"] == printgen.__version__
    assert m["command"][:2] == ["printgen", command]
    assert inputs <= set(m["inputs"]), m["inputs"]
    assert all(len(v["sha256"]) == 64 for v in m["inputs"].values())
    assert m["environment"]["python"] and "numpy" in m["environment"]["packages"]
    capsys.readouterr()
    assert main(["check", str(out)]) == 0
    assert f"printgen {printgen.__version__}" in capsys.readouterr().out


def test_verify_design_series_and_testpieces_manifests(tmp_path, capsys):
    proto = coarse_simple_file(tmp_path)
    _, d = planned(proto, 40)
    design = tmp_path / "design.json"
    design.write_text(dumps(d.to_dict()))
    assert main(["verify", str(proto), "-s", "40", "--design", str(design), "--out",
                 str(tmp_path / "v")]) in (0, 3)
    check_provenance(tmp_path / "v", "verify", {"prototype", "design_file",
                                                  f"materials/{d.net.material}"}, capsys)
    diamond = tmp_path / "diamond.json"  # the test panel is a diamond net's
    diamond.write_text(dumps(reference_design_1_40().to_dict()))
    assert main(["testpieces", str(diamond), "--out", str(tmp_path / "t")]) == 0
    check_provenance(tmp_path / "t", "testpieces", {"design_file"}, capsys)
    small = tiny(tmp_path)
    assert main(["series", str(small), "--scales", "1,100", "--materials", "petg", "--serial",
                 "--out", str(tmp_path / "s")]) == 0
    check_provenance(tmp_path / "s", "series", {"prototype"}, capsys)
    assert main(["design", str(small), "--scale", "40", "--objective", "stiffness",
                 "--materials", "tpe", "--serial", "--out", str(tmp_path / "d")]) == 0
    check_provenance(tmp_path / "d", "design", {"prototype"}, capsys)
