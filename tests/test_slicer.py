"""Slicer profiles: PrusaSlicer .ini and CuraEngine settings, sliced by the real slicers."""

from __future__ import annotations

import dataclasses
import json
import os
import re
import subprocess

import numpy as np
import pytest
from conftest import require_shared, require_tool
from numpy.testing import assert_allclose

from printgen.errors import PrintabilityError
from printgen.inputs.materials import load_material
from printgen.inputs.printers import load_print_style, load_printer
from printgen.parts.gcode import read_gcode
from printgen.parts.slicer import (
    allowed_prusa_keys,
    prusa_ini_text,
    prusa_settings,
    write_prusa_ini,
)
from printgen.parts.slicer.cura import cura_cfg_text, cura_settings, write_cura_cfg
from printgen.scaling.record import Section

READBACK_VS_CHECKER_TOL = 1e-3  # two parsers of the same file: only E rounding differs
SKIRT_PATHS = 1  # the .ini asks for one skirt loop: the checker counts it, the read-back does not
SLICE_TIMEOUT_S = 120


def _setup(design, part):
    return (load_printer(design.printer), load_print_style(part.print_style),
            load_material(part.material))


def _ini(text: str) -> dict[str, str]:
    """The settings of an .ini (the preset names, *_settings_id, left out)."""
    return dict(ln.split(" = ", 1) for ln in text.splitlines()
                if ln and not ln.startswith("#") and "_settings_id = " not in ln)


def test_ini_follows_the_measured_rules(design_1_40):
    net = design_1_40.net
    printer, style, material = _setup(design_1_40, net)
    s = _ini(prusa_ini_text("net", net, printer, style, material))
    assert set(s) <= allowed_prusa_keys()
    bead = 1.15 * 0.6  # slicers.md: bead about 1.15 x the strand
    for k in ("perimeter_extrusion_width", "external_perimeter_extrusion_width",
              "first_layer_extrusion_width"):  # first layer width = bead width (pitfall 3)
        assert_allclose(float(s[k]), bead, rtol=1e-3)
    assert_allclose(float(s["min_bead_width"]), 0.85 * 0.6, rtol=1e-3)
    assert 0.85 * 0.6 < net.strand.bead_width_mm < bead  # one bead per strand in Arachne
    assert s["perimeter_generator"] == "arachne" and s["perimeters"] == "1"
    assert s["use_relative_e_distances"] == "1" and s["layer_gcode"] == "G92 E0"
    assert s["max_volumetric_speed"] == s["filament_max_volumetric_speed"] == "1.425"  # 0.95 x
    assert (s["first_layer_height"], s["layer_height"]) == ("0.35", "0.3")
    assert (s["first_layer_temperature"], s["bed_temperature"]) == ("230", "50")
    assert "M190 S[first_layer_bed_temperature]" in s["start_gcode"]
    assert "{" not in s["start_gcode"] and "\n" not in s["start_gcode"]


def test_allowed_keys_are_known_to_prusaslicer():
    exe = require_tool("prusa-slicer")
    out = subprocess.run([exe, "--help-fff"], capture_output=True, text=True, check=False,
                         timeout=SLICE_TIMEOUT_S).stdout
    known = {m.replace("-", "_") for ln in out.splitlines() if ln.startswith(" --")
             for m in re.findall(r"--([a-z0-9-]+)", ln)}
    assert len(known) > 250  # the full option list, not an error message
    assert sorted(allowed_prusa_keys() - known) == []


def test_cable_profiles_fill_the_eyelet_band(design_1_40):
    cable = design_1_40.cables[2]
    printer, style, material = _setup(design_1_40, cable)
    s = prusa_settings("cable", cable, printer, style, material)
    # eyelet band (6 - 3) / 2 = 1.5 mm = 3 beads of 0.5 mm -> 2 perimeter loops
    assert s["perimeters"] == "2"
    c = cura_settings("cable", cable, printer, style, material)
    assert c["wall_line_count"] == "2" and c["material_diameter"] == "1.75"
    assert c["relative_extrusion"] == "true" and c["machine_heated_bed"] == "true"
    flow = float(c["speed_print"]) * float(c["line_width"]) * 0.3
    assert flow <= material.print.max_volumetric_flow_mm3_per_s


@pytest.mark.parametrize("case", ["narrow strand", "zero passes", "larger than bed", "layers"])
def test_bad_designs_fail_before_any_profile_is_written(design_1_40, tmp_path, case):
    net = design_1_40.net
    printer, style, material = _setup(design_1_40, net)
    if case == "narrow strand":
        net, msg = dataclasses.replace(net, strand=Section(0.3, 1, (0.35, 0.3))), "below 0.425"
    elif case == "zero passes":
        net, msg = dataclasses.replace(net, strand=Section(0.6, 1, ())), "0 passes"
    elif case == "larger than bed":
        printer = dataclasses.replace(printer, bed_x_mm=250.0, bed_y_mm=250.0)
        msg = "does not fit"
    else:
        net = dataclasses.replace(net, strand=Section(0.6, 1, (0.35, 0.3, 0.25)))
        msg = "vary above the first layer"
    out = tmp_path / "net.ini"
    with pytest.raises(PrintabilityError, match=msg):
        write_prusa_ini(out, "net", net, printer, style, material)
    assert not out.exists()
    with pytest.raises(PrintabilityError, match="CuraEngine 4.13 cannot slice the diamond net"):
        write_cura_cfg(tmp_path / "net.cfg", "net", net, printer, style, material)
    assert not (tmp_path / "net.cfg").exists()


# ----------------------------------------------------------------------------- slicing
def _net_stl(net, path):
    """The net's mesh (printgen.parts.geometry.solid), as the lab would slice it."""
    pytest.importorskip("manifold3d")
    from printgen.parts.geometry.solid import net_solid

    net_solid(net).export(path)
    return path


def _cable_stl(cable, path):
    pytest.importorskip("manifold3d")
    from printgen.parts.geometry.solid import cable_solid

    cable_solid(cable).export(path)
    return path


def _run(script, stl, cfg, tmp_path, *args):
    env = dict(os.environ, OUT_DIR=str(tmp_path), PYTHON=os.environ.get("PYTHON", "python3"))
    r = subprocess.run(["bash", str(script), str(stl), str(cfg), *args], capture_output=True,
                       text=True, env=env, timeout=SLICE_TIMEOUT_S, check=False)
    return r.returncode, r.stdout.strip().splitlines()[-1] if r.stdout.strip() else r.stderr


@pytest.mark.parametrize("size_mm", [(40.0, 60.0), (330.0, 100.0)], ids=["reduced", "full"])
def test_prusaslicer_slices_a_generated_net_with_one_bead_per_strand(design_1_40, tmp_path,
                                                                     size_mm):
    require_tool("prusa-slicer")
    script = require_shared("tools/gcode/slice_check.sh")
    net = dataclasses.replace(design_1_40.net, width_mm=size_mm[0], height_mm=size_mm[1])
    printer, style, material = _setup(design_1_40, net)
    ini = write_prusa_ini(tmp_path / "net.ini", "net", net, printer, style, material)
    stl = _net_stl(net, tmp_path / "net.stl")
    rc, summary = _run(script, stl, ini, tmp_path, "--width", f"{net.strand.width_mm}",
                       "--area-model", "stadium", "--layers", f"{len(net.strand.layer_heights_mm)}",
                       "--max-flow", f"{material.print.max_volumetric_flow_mm3_per_s:g}")
    assert rc == 0, summary
    assert summary.startswith("SLICE-CHECK OK")
    rep = json.loads((tmp_path / "net.prusa.json").read_text())
    # read-back of the slicer's own G-code agrees with the independent checker
    rb = read_gcode(tmp_path / "net.prusa.gcode", filament_diameter_mm=printer.filament_diameter_mm)
    assert len(rb.layer_z_mm) == rep["layer_count"] == 3
    # the checker totals every extrusion; the read-back leaves the skirt out of the part
    assert_allclose(rb.volume_mm3 + rb.prime_volume_mm3, rep["extruded_volume_mm3"],
                    rtol=READBACK_VS_CHECKER_TOL)
    assert rb.path_count + SKIRT_PATHS == rep["paths"]["count"]
    outer = np.array([rep["bounds_extrusion"][k] for k in "XY"])  # skirt included
    assert np.all(rb.bounds_mm[0, :2] > outer[:, 0]) and np.all(rb.bounds_mm[1, :2] < outer[:, 1])


def test_prusaslicer_slices_a_cable(design_1_40, tmp_path):
    require_tool("prusa-slicer")
    script = require_shared("tools/gcode/slice_check.sh")
    cable = design_1_40.cables[2]
    printer, style, material = _setup(design_1_40, cable)
    ini = write_prusa_ini(tmp_path / "cable.ini", "cable", cable, printer, style, material)
    rc, summary = _run(script, _cable_stl(cable, tmp_path / "cable.stl"), ini, tmp_path,
                       "--width", f"{cable.section.bead_width_mm}", "--area-model", "stadium",
                       "--layers", "2")
    assert rc == 0, summary


def test_curaengine_slices_a_cable(design_1_40, tmp_path):
    require_tool("CuraEngine")
    script = require_shared("tools/gcode/slice_check_cura.sh")
    cable = design_1_40.cables[2]
    printer, style, material = _setup(design_1_40, cable)
    cfg = tmp_path / "cable.cfg"
    cfg.write_text(cura_cfg_text("cable", cable, printer, style, material))
    rc, summary = _run(script, _cable_stl(cable, tmp_path / "cable.stl"), cfg, tmp_path,
                       "--width", f"{cable.section.bead_width_mm}", "--layers", "2",
                       "--max-flow", f"{material.print.max_volumetric_flow_mm3_per_s:g}")
    assert rc == 0, summary
    assert summary.startswith("SLICE-CHECK OK slicer=CuraEngine-4.13")
    # printgen's own CuraEngine command line gives the same print as the shared script
    from printgen.parts.slicer.cura import cura_engine_args, find_definitions

    defs = find_definitions()
    out = tmp_path / "own.gcode"
    env = dict(os.environ, CURA_ENGINE_SEARCH_PATH=f"{defs}:{defs.parent / 'extruders'}")
    args = cura_engine_args(cura_settings("cable", cable, printer, style, material),
                            tmp_path / "cable.stl", out, defs)
    subprocess.run(args, env=env, capture_output=True, timeout=SLICE_TIMEOUT_S, check=True)
    mine = read_gcode(out, filament_diameter_mm=printer.filament_diameter_mm)
    theirs = read_gcode(tmp_path / "cable.cura.gcode",
                        filament_diameter_mm=printer.filament_diameter_mm)
    assert_allclose(mine.volume_per_layer_mm3, theirs.volume_per_layer_mm3, rtol=1e-9)
    assert len(mine.layer_z_mm) == len(cable.section.layer_heights_mm)


def _cura_keys(node: dict) -> set[str]:
    keys = set()
    for k, v in node.items():
        keys.add(k)
        keys |= _cura_keys(v.get("children", {}))
    return keys


def test_cura_keys_exist_in_the_definitions(design_1_40):
    from printgen.parts.slicer.cura import find_definitions

    require_tool("CuraEngine")
    defs = find_definitions()
    if defs is None:  # same rule as the slicers: skip locally, fail in CI
        msg = "fdmprinter.def.json not found (bash scripts/setup.sh --with-slicers extracts it)"
        if os.environ.get("PRINTGEN_REQUIRE_SLICERS") or os.environ.get("CI"):
            pytest.fail(msg)
        pytest.skip(msg)
    known = set()
    for name in ("fdmprinter.def.json", "fdmextruder.def.json"):
        known |= _cura_keys(json.loads((defs / name).read_text())["settings"])
    assert len(known) > 400  # the whole tree was read
    cable = design_1_40.cables[2]
    s = cura_settings("cable", cable, *_setup(design_1_40, cable))
    assert sorted(set(s) - known) == []
