"""Bed layout, STL and 3MF exports; the 3MF slices alone with its embedded PrusaSlicer
settings; STEP when CadQuery is installed. Bad input raises before any file is written."""

from __future__ import annotations

import dataclasses
import io
import subprocess
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import pytest
from conftest import require_module, require_tool

from printgen.errors import GeometryError, InputError, PrintabilityError
from printgen.inputs.materials import load_material
from printgen.inputs.printers import load_print_style, load_printer
from printgen.parts.export import (
    layout_parts,
    place_mesh,
    prusa_config_from_ini,
    stl_bytes,
    threemf_bytes,
    usable_bed_mm,
    write_3mf,
    write_plate,
    write_stl,
)
from printgen.parts.export.bed import ANGLE_STEP_DEG, PART_GAP_MM
from printgen.parts.geometry.cable import CIRCLE_SEGMENTS, circle_scale
from printgen.parts.geometry.solid import cable_outline, cable_solid, net_solid
from printgen.parts.slicer.prusa import prusa_ini_text
from printgen.scaling.record import Section

trimesh = pytest.importorskip("trimesh")

FLOAT32 = 1e-4  # mm: STL stores float32 coordinates (~2e-5 mm near 350 mm)
XML_DIGITS = 1e-6  # mm: 3MF vertices are written with 6 decimals
ROUND_OFF = 1e-9  # mm: float64 transforms of the meshes
SLICE_TIMEOUT_S = 300
NS = {"m": "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"}


@pytest.fixture(scope="module")
def printer():
    return load_printer("generic-350")


@pytest.fixture(scope="module")
def cables():
    from conftest import reference_design_1_40

    return reference_design_1_40().cables


@pytest.fixture(scope="module")
def plate(cables, printer):
    """The four 1:40 cables on one plate, and the PETG cable settings."""
    c = cables[0]
    ini = prusa_ini_text("cable", c, printer, load_print_style(c.print_style),
                         load_material(c.material))
    return layout_parts([(f"cable-{c.name}", cable_solid(c)) for c in cables], printer), ini


def test_a_part_that_fits_is_centred_on_the_bed_unturned(cables, printer):
    mesh, angle = place_mesh(cable_solid(cables[2]), printer, "cable-left")
    lo, hi = mesh.bounds
    assert angle == 0.0
    np.testing.assert_allclose((lo + hi)[:2] / 2, [printer.bed_x_mm / 2, printer.bed_y_mm / 2],
                               atol=ROUND_OFF)
    assert lo[2] == pytest.approx(0.0, abs=ROUND_OFF)


def test_a_long_cable_is_turned_by_the_smallest_angle_that_fits(cables, printer):
    """The 345 mm cable with 6 mm eyelets spans L cos(a) + 2 ro along x: it fits 340 mm from
    a = acos(334 / 345) = 14.5 deg, i.e. the 15 deg step of the 0.5 deg sweep."""
    c = cables[0]
    ro = c.eyelet_outer_mm / 2 * circle_scale(CIRCLE_SEGMENTS)
    usable = usable_bed_mm(printer)[0]
    limit = np.degrees(np.arccos((usable - 2 * ro) / c.length_mm))
    expected = np.ceil(limit / ANGLE_STEP_DEG) * ANGLE_STEP_DEG
    mesh, angle = place_mesh(cable_solid(c), printer, "cable-top")
    assert angle == pytest.approx(expected, abs=ROUND_OFF)
    lo, hi = mesh.bounds
    assert np.all(lo[:2] >= printer.bed_margin_mm - ROUND_OFF)
    assert np.all(hi[:2] <= [printer.bed_x_mm - printer.bed_margin_mm,
                             printer.bed_y_mm - printer.bed_margin_mm])


def test_four_cables_share_one_plate_without_overlap(plate, cables, printer):
    placed, _ = plate
    assert [p.name for p in placed] == [f"cable-{c.name}" for c in cables]
    boxes = [p.mesh.bounds[:, :2] for p in placed]
    for k, (lo, hi) in enumerate(boxes):
        assert np.all(lo >= printer.bed_margin_mm - ROUND_OFF)
        assert np.all(hi <= np.array([printer.bed_x_mm, printer.bed_y_mm])
                      - printer.bed_margin_mm + ROUND_OFF)
        for lo2, hi2 in boxes[k + 1:]:  # footprints at least the gap apart on x or y
            gap = np.maximum(lo2 - hi, lo - hi2)
            assert gap.max() >= PART_GAP_MM - ROUND_OFF
    for p, c in zip(placed, cables, strict=True):  # moved and turned, not changed
        assert p.mesh.volume == pytest.approx(cable_solid(c).volume, rel=1e-12)  # round-off


def test_a_part_larger_than_the_bed_is_rejected_before_writing(cables, printer, tmp_path):
    long = dataclasses.replace(cables[0], length_mm=600.0)
    out = tmp_path / "long.3mf"
    with pytest.raises(PrintabilityError, match=r"part 606\.0 x 6\.0 mm does not fit the usable "
                       r"340 x 340 mm .* not even turned diagonally .* larger bed "
                       r".* larger lambda"):
        write_plate(out, [("cable-long", cable_solid(long))], printer)
    assert not out.exists() and not list(tmp_path.iterdir())


def test_a_part_taller_than_the_printer_is_rejected(printer):
    tower = trimesh.creation.box(extents=(10.0, 10.0, printer.max_height_mm + 1))
    with pytest.raises(PrintabilityError, match="301 mm high exceeds the 300 mm build height"):
        place_mesh(tower, printer, "tower")


def test_parts_that_fit_alone_but_not_together_are_rejected(cables, printer, tmp_path):
    top = cable_solid(cables[0])
    parts = [(f"top-{k}", top) for k in range(4)]  # four turned 345 mm cables: ~396 mm of rows
    with pytest.raises(PrintabilityError, match="put them on separate plates"):
        write_plate(tmp_path / "four.3mf", parts, printer)
    assert not list(tmp_path.iterdir())


def test_stl_round_trip(plate, tmp_path):
    (placed, _) = plate
    mesh = placed[0].mesh
    path = write_stl(tmp_path / "cable.stl", mesh)
    data = path.read_bytes()
    assert data == stl_bytes(mesh)
    assert len(data) == 84 + 50 * len(mesh.faces)  # binary STL: header, count, 50 B a facet
    back = trimesh.load(io.BytesIO(data), file_type="stl")
    assert back.is_watertight and len(back.faces) == len(mesh.faces)
    # float32 coordinates near 300 mm on the bed: about 1e-5 relative on the volume
    assert back.volume == pytest.approx(mesh.volume, rel=2e-5)
    np.testing.assert_allclose(back.bounds, mesh.bounds, atol=FLOAT32)


def test_an_open_mesh_is_not_written(plate, tmp_path):
    (placed, _) = plate
    holed = placed[0].mesh.copy()
    holed.update_faces(np.arange(len(holed.faces)) != 0)  # drop one triangle
    with pytest.raises(GeometryError, match="not a closed, outward-facing solid"):
        write_stl(tmp_path / "holed.stl", holed, "holed")
    with pytest.raises(GeometryError, match="holed"):
        write_3mf(tmp_path / "holed.3mf", [("holed", holed)])
    assert not list(tmp_path.iterdir())


def _read_3mf(data: bytes):
    with zipfile.ZipFile(io.BytesIO(data)) as z:
        assert z.testzip() is None  # every member's CRC is right
        names = set(z.namelist())
        model = ET.fromstring(z.read("3D/3dmodel.model"))
        config = (z.read("Metadata/Slic3r_PE.config").decode()
                  if "Metadata/Slic3r_PE.config" in names else None)
    return names, model, config


def test_3mf_holds_named_objects_in_mm_and_the_settings(plate, tmp_path):
    placed, ini = plate
    parts = [(p.name, p.mesh) for p in placed]
    path = write_plate(tmp_path / "cables.3mf", parts, load_printer("generic-350"), ini)
    data = (tmp_path / "cables.3mf").read_bytes()
    assert [p.name for p in path] == [n for n, _ in parts]
    names, model, config = _read_3mf(data)
    assert {"[Content_Types].xml", "_rels/.rels", "3D/3dmodel.model"} <= names
    assert model.get("unit") == "millimeter"
    objects = model.findall("m:resources/m:object", NS)
    assert [o.get("name") for o in objects] == [n for n, _ in parts]
    assert len(model.findall("m:build/m:item", NS)) == len(parts)
    for obj, (_, mesh) in zip(objects, parts, strict=True):
        v = np.array([[float(x.get(k)) for k in "xyz"]
                      for x in obj.findall("m:mesh/m:vertices/m:vertex", NS)])
        f = np.array([[int(t.get(k)) for k in ("v1", "v2", "v3")]
                      for t in obj.findall("m:mesh/m:triangles/m:triangle", NS)])
        back = trimesh.Trimesh(v, f, process=False)
        assert back.is_watertight and len(f) == len(mesh.faces)
        np.testing.assert_allclose(back.bounds, mesh.bounds, atol=XML_DIGITS)
    lines = config.splitlines()
    assert lines[0] == "; generated by PrusaSlicer 2.5.0"  # slicers.md section 8
    settings = [ln.strip() for ln in ini.splitlines() if "=" in ln and not ln.startswith("#")]
    assert lines[1:] == [f"; {k.strip()} = {v.strip()}"
                         for k, v in (s.split("=", 1) for s in settings)]
    assert "; bed_temperature = 80" in lines  # PETG


def test_3mf_is_reproducible_and_the_config_idempotent(plate):
    placed, ini = plate
    parts = [(p.name, p.mesh) for p in placed[:1]]
    config = prusa_config_from_ini(ini)
    assert prusa_config_from_ini(config) == config
    assert threemf_bytes(parts, ini) == threemf_bytes(parts, config)
    names, _, none = _read_3mf(threemf_bytes(parts))
    assert none is None and "Metadata/Slic3r_PE.config" not in names


@pytest.mark.parametrize("parts, config, error, message", [
    ("none", None, GeometryError, "at least one part"),
    ("dup", None, GeometryError, "repeated: a"),
    ("blank", None, GeometryError, "non-empty name"),
    ("one", "# only a comment\n", InputError, "no 'key = value' line"),
    ("one", "bad key = 1\n", InputError, "no valid key"),
])
def test_bad_3mf_input_writes_nothing(plate, tmp_path, parts, config, error, message):
    mesh = plate[0][0].mesh
    parts = {"dup": [("a", mesh), ("a", mesh)], "blank": [(" ", mesh)],
             "one": [("a", mesh)], "none": []}[parts]
    with pytest.raises(error, match=message):
        write_3mf(tmp_path / "bad.3mf", parts, config)
    assert not list(tmp_path.iterdir())


def test_a_bad_net_fails_before_any_export(tmp_path):
    from conftest import reference_design_1_40

    net = dataclasses.replace(reference_design_1_40().net, strand=Section(0.6, 1, (0.0,)))
    with pytest.raises(GeometryError, match="thickness = 0.0 mm"):
        write_stl(tmp_path / "net.stl", net_solid(net))
    assert not list(tmp_path.iterdir())


@pytest.mark.slow
def test_prusaslicer_slices_the_cable_plate_alone_with_its_settings(plate, tmp_path):
    """slicers.md, section 8: the 3MF carries its settings (here PETG at 240/80 degC)."""
    exe = require_tool("prusa-slicer")
    placed, ini = plate
    path = write_3mf(tmp_path / "cables.3mf", [(p.name, p.mesh) for p in placed], ini)
    out = tmp_path / "cables.gcode"
    r = subprocess.run([exe, "--export-gcode", "--output", str(out), str(path)],
                       capture_output=True, text=True, timeout=SLICE_TIMEOUT_S, check=False)
    assert r.returncode == 0, r.stderr[-500:]
    text = out.read_text()
    settings = dict(line[2:].split(" = ", 1) for line in text.splitlines()
                    if line.startswith("; ") and " = " in line)
    wanted = {k.strip(): v.strip() for k, v in (ln.split("=", 1) for ln in ini.splitlines()
                                                if "=" in ln and not ln.startswith("#"))}
    for key in ("temperature", "bed_temperature", "layer_height", "first_layer_height",
                "extrusion_width", "perimeters"):
        assert settings[key] == wanted[key], key
    for p in placed:  # every object printed: PrusaSlicer labels each with its name
        assert f"; printing object {p.name}" in text, p.name


@pytest.mark.slow
def test_prusaslicer_slices_the_net_with_its_loops_and_eyelets_from_its_3mf(tmp_path):
    """The 1:40 net with its loops and corner eyelets (335.4 mm wide with its corner rings:
    turned on the 340 mm usable bed) slices alone with its TPE settings."""
    from conftest import reference_design_1_40

    from printgen.parts.geometry.solid import attachment_for

    exe = require_tool("prusa-slicer")
    d = reference_design_1_40()
    printer = load_printer(d.printer)
    ini = prusa_ini_text("net", d.net, printer, load_print_style(d.net.print_style),
                         load_material(d.net.material))
    path = tmp_path / "net.3mf"
    att = attachment_for(d, hole_compensation_mm=printer.hole_compensation_mm)
    write_plate(path, [("net", net_solid(d.net, att))], printer, ini)
    out = tmp_path / "net.gcode"
    r = subprocess.run([exe, "--export-gcode", "--output", str(out), str(path)],
                       capture_output=True, text=True, timeout=SLICE_TIMEOUT_S, check=False)
    assert r.returncode == 0, r.stderr[-500:]
    text = out.read_text()
    assert "; printing object net" in text
    for key in ("temperature", "filament_type", "layer_height", "first_layer_height"):
        value = next(ln.split("=", 1)[1].strip() for ln in ini.splitlines()
                     if ln.split("=", 1)[0].strip() == key)
        assert f"; {key} = {value}\n" in text, key


def test_step_needs_cadquery_or_says_how(cables, tmp_path):
    from printgen.parts.geometry.cad import write_step

    outline = cable_outline(cables[0])
    try:
        import cadquery  # noqa: F401
    except ImportError:
        with pytest.raises(GeometryError, match=r"pip install 'printgen\[cad\]'"):
            write_step(tmp_path / "cable.step", outline, 0.6)
        assert not list(tmp_path.iterdir())
        return
    path = write_step(tmp_path / "cable.step", outline, 0.6)
    assert path.read_bytes().startswith(b"ISO-10303-21")


def test_step_rejects_a_flat_part_before_cadquery(cables, tmp_path):
    from printgen.parts.geometry.cad import write_step

    with pytest.raises(GeometryError, match="thickness = 0.0 mm"):
        write_step(tmp_path / "flat.step", cable_outline(cables[0]), 0.0)
    assert not list(tmp_path.iterdir())


def test_step_of_a_plate_with_many_holes_is_one_solid_in_strips(tmp_path):
    """A face with more holes than STEP_HOLES_PER_FACE is written as strips glued into one
    solid: read back, one valid solid of the outline's volume, its top cut into strips."""
    cq = require_module("cadquery")
    import shapely
    from shapely.geometry import Point, box

    from printgen.parts.geometry.cad import STEP_HOLES_PER_FACE, STEP_VOLUME_TOL, write_step

    n = 2 * STEP_HOLES_PER_FACE + 10  # three strips
    holes = [Point(3.0 * i + 1.5, 1.5 + 0.4 * (i % 3 - 1)).buffer(0.8, 8) for i in range(n)]
    plate = box(0.0, 0.0, 3.0 * n, 3.0).difference(shapely.unary_union(holes))
    path = write_step(tmp_path / "plate.step", plate, 0.5)
    solids = cq.importers.importStep(str(path)).solids().vals()
    assert len(solids) == 1 and solids[0].isValid()
    assert abs(solids[0].Volume() / (plate.area * 0.5) - 1) < STEP_VOLUME_TOL
    top = [f for f in solids[0].Faces() if abs(f.Center().z - 0.5) < ROUND_OFF]
    assert len(top) == 3
