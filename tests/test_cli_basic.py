"""`printgen targets`, `select`, `profiles`: JSON keys, tables, exit codes and messages."""

from __future__ import annotations

import json

import pytest
from proto_files import REALISTIC, write_variant

from printgen.cli import main


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_targets_json(capsys):
    code, out, _ = run(capsys, "targets", REALISTIC, "--scale", 40, "--json")
    assert code == 0
    data = json.loads(out)
    assert set(data) == {"prototype", "scale", "targets", "pi_groups", "flow", "warnings"}
    assert data["targets"]["cable_ea"]["model"] == pytest.approx(706.858, rel=1e-5)
    assert data["targets"]["width"]["exponent"] == -1
    assert set(data["pi_groups"]["model"]) == {
        "pi1_width_over_height", "pi2_mesh_over_height", "pi3_strand_d_over_height",
        "pi4_froude", "pi5_modulus_over_dynamic_pressure"}
    assert data["flow"]["reynolds"] > 2500 and data["warnings"] == []


def test_targets_json_is_reproducible(capsys):
    first = run(capsys, "targets", REALISTIC, "-s", 40, "--json")[1]
    assert run(capsys, "targets", REALISTIC, "-s", 40, "--json")[1] == first


def test_targets_table(capsys):
    code, out, _ = run(capsys, "targets", REALISTIC, "--scale", 40)
    assert code == 0 and "border cable axial stiffness E*A" in out and "Re = 7730" in out


def test_select_json_and_table(capsys):
    code, out, _ = run(capsys, "select", REALISTIC, "--scale", 40, "--json")
    assert code == 0
    data = json.loads(out)
    best = data["cable"]["ranked"][0]
    assert (best["material"], best["section"]["width_mm"], best["section"]["thickness_mm"]) == (
        "petg", 0.9, 0.6)
    assert {"error", "pi3_deviation", "safety_factor", "feasible", "modulus_source"} <= set(best)
    assert any(c["material"] == "tpe" and c["section"]["thickness_mm"] == pytest.approx(0.95)
               for c in data["net"]["ranked"])
    code, out, _ = run(capsys, "select", REALISTIC, "--scale", 40)
    assert code == 0 and "Choice:" in out and "PETG" in out


def test_profiles_list_and_show(capsys):
    code, out, _ = run(capsys, "profiles", "list", "--json")
    assert code == 0 and "petg" in [p["name"] for p in json.loads(out)["materials"]]
    code, out, _ = run(capsys, "profiles", "show", "petg", "--json")
    data = json.loads(out)
    assert data["kind"] == "materials"
    assert data["profile"]["measured_modulus"]["value"] == pytest.approx(1.30e9)
    code, out, _ = run(capsys, "profiles", "show", "generic-350")
    assert code == 0 and "nozzle_diameter_mm" in out


@pytest.mark.parametrize("argv, message", [
    (["targets", REALISTIC, "--scale", "0.5"], "scale = 0.5 is below 1"),
    (["targets", "missing.toml", "--scale", "40"], "file not found: missing.toml"),
    (["select", REALISTIC, "--scale", "40", "--materials", "nylon"],
     "no material profile named 'nylon'"),
    (["select", REALISTIC, "--scale", "40", "--printer", "nothere"],
     "no printer profile named 'nothere'; known: generic-350, prusa-mk4"),
    (["profiles", "show", "unobtainium"], "no profile named 'unobtainium'"),
])
def test_bad_input_exits_2_with_message(capsys, argv, message):
    code, out, err = run(capsys, *argv)
    assert code == 2 and message in err and "Traceback" not in err and out == ""


def test_unknown_key_via_cli(capsys, tmp_path):
    bad = write_variant(tmp_path, {("flow", "speed_m_per_s"): 3.0})
    code, _, err = run(capsys, "targets", bad, "--scale", 40)
    assert code == 2 and "unknown key 'speed_m_per_s'; allowed keys:" in err
