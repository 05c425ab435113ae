"""Bad input fails where it enters, with the value, the limit and the fix."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest
from proto_files import REALISTIC, write_variant

from printgen.errors import InputError, ProfileError
from printgen.inputs.materials import load_material
from printgen.inputs.printers import load_printer
from printgen.inputs.prototype import load_prototype


@pytest.mark.parametrize("edit, message", [
    ({("barrier", "colour"): "red"}, r"unknown key 'colour'; allowed keys: anchors, height_m"),
    ({("barrier", "width_m"): -13.2}, r"width_m = -13.2 is out of range: it must be >= 0.1 m"),
    ({("barrier", "width_m"): 0.0}, r"width_m = 0.0 is out of range: it must be >= 0.1 m"),
    ({("barrier", "width_m"): float("nan")}, r"width_m = nan is not finite"),
    ({("barrier", "width_m"): "13"}, r"width_m = '13' is not a number"),
    ({("barrier", "height_m"): None}, r"missing key 'height_m'"),
    ({("net", "pattern"): "hexagon"}, r"pattern = 'hexagon' is not one of: diamond, square"),
    ({("net", "mesh_x_m"): 8.0}, r"mesh_x_m = 8 m exceeds half the barrier"),
    ({("net", "panel_law", "kappa_kn_per_m_per_m"): [250.0]}, r"one kappa per segment"),
    ({("net", "panel_law", "knee_strain_percent"): [-20.0]}, r"positive finite numbers"),
    ({("net", "panel_law"): None}, r"give strand_modulus_gpa or a \[net.panel_law\]"),
    ({("flow", "velocity_m_per_s"): 500.0}, (r"velocity_m_per_s = 500.0 is out of range: it "
                                            r"must be <= 50 m/s")),
    ({("flume", "froude_min"): True}, r"froude_min = True is not a number"),
    ({("flume", "sensor_force_n"): -1.0}, r"\[flume\]: sensor_force_n = -1.0 is out of range: "
                                          r"it must be >= 0 N"),
    ({("flume", "sensor_force_n"): 500.0}, r"sensor_force_n = 500.0 is out of range: it must "
                                           r"be <= 100 N"),
    ({("model", "mesh_x_mm"): 0}, r"mesh_x_mm = 0 is out of range"),
])
def test_bad_prototype_values(tmp_path, edit, message):
    with pytest.raises(InputError, match=message):
        load_prototype(write_variant(tmp_path, edit))


def test_missing_file_names_the_path(tmp_path):
    with pytest.raises(InputError, match="file not found: .*nothere.toml"):
        load_prototype(tmp_path / "nothere.toml")


def test_broken_toml_says_so(tmp_path):
    p = tmp_path / "broken.toml"
    p.write_text("name = \n")
    with pytest.raises(InputError, match="not valid TOML"):
        load_prototype(p)


def test_utf8_with_a_byte_order_mark_reads_and_utf16_is_named(tmp_path):
    """Windows editors write UTF-8 with a BOM (read as UTF-8), PowerShell's `>` UTF-16
    (refused, naming the encoding to save in)."""
    text = Path(REALISTIC).read_text("utf-8")
    bom = tmp_path / "bom.toml"
    bom.write_bytes(b"\xef\xbb\xbf" + text.encode("utf-8"))
    same = dataclasses.replace(load_prototype(REALISTIC), path=None)
    assert dataclasses.replace(load_prototype(bom), path=None) == same
    utf16 = tmp_path / "utf16.toml"
    utf16.write_bytes(text.encode("utf-16"))
    with pytest.raises(InputError, match="not utf-8 text.*save it as utf-8"):
        load_prototype(utf16)


def test_unknown_material_lists_the_known_ones():
    with pytest.raises(ProfileError, match=r"no material profile named 'nylon'; known: abs, asa"):
        load_material("nylon")


def test_profile_with_unknown_key(tmp_path, monkeypatch):
    (tmp_path / "printers").mkdir()
    (tmp_path / "printers" / "odd.toml").write_text(
        'inherits = "generic-350"\nname = "Odd"\nbed_z_mm = 300\n')
    monkeypatch.setenv("PRINTGEN_PROFILES", str(tmp_path))
    with pytest.raises(InputError, match=r"unknown key 'bed_z_mm'; allowed keys: .*bed_x_mm"):
        load_printer("odd")


def test_inherited_profile_overrides_parent():
    p = load_printer("prusa-mk4")
    assert (p.nozzle_diameter_mm, p.bed_x_mm, p.bed_y_mm) == (0.4, 250.0, 210.0)
    assert p.gcode_flavor == load_printer("generic-350").gcode_flavor  # inherited


def test_inheritance_cycle_is_an_error(tmp_path, monkeypatch):
    d = tmp_path / "prints"
    d.mkdir()
    (d / "a.toml").write_text('inherits = "b"\n')
    (d / "b.toml").write_text('inherits = "a"\n')
    monkeypatch.setenv("PRINTGEN_PROFILES", str(tmp_path))
    from printgen.inputs.printers import load_print_style
    with pytest.raises(ProfileError):
        load_print_style("a")


def test_measured_values_carry_provenance():
    for name in ("asa", "petg", "pla"):
        m = load_material(name)
        assert m.modulus()[1] == "measured"
        assert "Lambert et al. 2023" in m.measured_modulus.source
    e, src = load_material("psu").modulus()
    assert src == "datasheet" and e == pytest.approx(5.17e9)
    assert load_material("tpe").panel_law.kappas == (30e3, 6e3)
    assert REALISTIC.exists()


def test_sensor_force_is_an_input_defaulting_to_the_papers(tmp_path):
    """[flume] sensor_force_n: 1 N when not given (Lambert et al. 2023's string
    potentiometers), the file's value otherwise, in N."""
    assert load_prototype(REALISTIC).flume.sensor_force == 1.0
    p = load_prototype(write_variant(tmp_path, {("flume", "sensor_force_n"): 0.01}))
    assert p.flume.sensor_force == 0.01
