"""Slicer files a lab imports as presets: the PrusaSlicer config bundle (print and filament
presets on top of the lab's own printer preset, their names in the 3MF), the Cura profile and
its settings table, and every bundled printer x print style pair on the bundled examples."""

from __future__ import annotations

import configparser
import csv
import dataclasses
import io
import json
import os
import re
import subprocess
import zipfile
from pathlib import Path

import pytest
from conftest import reference_design_1_40, require_shared, require_tool
from proto_files import REALISTIC, SIMPLE, write_variant

from printgen.errors import DesignError, PrintabilityError
from printgen.inputs.materials import load_material
from printgen.inputs.printers import load_print_style, load_printer
from printgen.inputs.profiles import list_profiles
from printgen.parts.export import threemf_bytes
from printgen.parts.slicer.cura import (
    CURA_CONTAINER_VERSION,
    CURA_DEFINITION,
    CURA_QUALITY_TYPE,
    CURA_SETTING_VERSION,
    TABLE_COLUMNS,
    cura_profile_keys,
    cura_settings,
    cura_table_csv,
    curaprofile_bytes,
    find_definitions,
)
from printgen.parts.slicer.prusa import (
    PRESET_KINDS,
    SETTINGS_IDS,
    design_presets,
    presets_ini_text,
    prusa_bundle_text,
    prusa_key_presets,
    prusa_presets,
)

SLICE_TIMEOUT_S = 300
PRUSA_PROFILES = Path("/usr/share/PrusaSlicer/profiles")  # the vendor bundles prusa-slicer ships
# a stock printer preset with a 350 x 350 mm bed and a 0.5 mm nozzle, as the 1:40 design's
# generic-350: the 335 mm net fits its bed, and its nozzle is in the presets' range
STOCK = ("Creality.ini", "Creality Ender-5 Plus (0.5 mm nozzle)")
# the stock preset's bed_shape starts at 5,5 while its G28 goes to 0,0: the homing position
# lies this far outside the printable area (the checker's bed test counts it)
STOCK_HOME_OUTSIDE_MM = 5.0


def _bundle(text: str) -> configparser.RawConfigParser:
    """Parse a config bundle as boost's read_ini does: duplicate sections or keys are errors,
    `#` lines are comments, keys keep their case."""
    cp = configparser.RawConfigParser(strict=True, interpolation=None, delimiters=("=",),
                                      comment_prefixes=("#", ";"), inline_comment_prefixes=None)
    cp.optionxform = str  # type: ignore[assignment,method-assign]
    cp.read_string(text)
    return cp


def _flat(text: str) -> dict[str, str]:
    return dict((k.strip(), v.strip()) for k, v in (ln.split("=", 1) for ln in text.splitlines()
                                                    if "=" in ln and not ln.startswith("#")))


@pytest.fixture(scope="module")
def design():
    return reference_design_1_40()


@pytest.fixture(scope="module")
def presets(design):
    return design_presets(design, load_printer(design.printer))


def test_bundle_holds_one_section_per_preset_with_only_its_own_keys(presets, design):
    cp = _bundle(prusa_bundle_text(list(presets.values())))
    kinds = {s.split(":", 1)[0] for s in cp.sections() if ":" in s}
    assert kinds == set(PRESET_KINDS)
    groups = prusa_key_presets()
    for section in cp.sections():
        if section == "presets":
            continue
        kind, name = section.split(":", 1)
        keys = set(cp[section]) - {"compatible_printers_condition"}
        # a print or filament preset with a printer key would replace the lab's printer
        assert {groups[k] for k in keys} == {kind}, section
        assert name == name.strip() and not re.search(r'[\[\];"]', name)
    # the four cables share their print and filament presets; one printer preset
    assert sorted(cp.sections()) == sorted(
        ["print:printgen net TPE 0.6 x 0.95 mm (net-3pass)",
         "print:printgen cable PETG 0.9 x 0.6 mm (cable-4pass)",
         "filament:printgen TPE 1.75 mm", "filament:printgen PETG 1.75 mm",
         "printer:printgen Generic 350 x 350 (0.5 mm nozzle)", "presets"])
    # the import selects printgen's print and filament presets, not its printer: the lab's
    # own printer stays active
    assert set(cp["presets"]) == {"print", "filament"}
    for kind, name in cp["presets"].items():
        assert f"{kind}:{name}" in cp.sections()
    # every setting of every part is in its presets: the bundle loses nothing
    for p in presets.values():
        for kind in PRESET_KINDS:
            section = cp[f"{kind}:{p.names[kind]}"]
            assert {k: section[k] for k in p.settings[kind]} == {
                k: v.replace("\n", "\\n") for k, v in p.settings[kind].items()}


def test_print_presets_admit_the_nozzles_their_layers_and_beads_fit(presets, design):
    """net: 0.35 mm first layer <= 0.75 x nozzle -> nozzle >= 0.467; 0.6 mm bead >= 0.85 x
    nozzle -> nozzle <= 0.705 (rounded inwards to 0.001 mm); cable: 0.3 mm layers and 0.45 mm
    beads -> 0.4 ... 0.529 mm."""
    assert presets["net"].compatible == ("nozzle_diameter[0]>=0.467 and "
                                         "nozzle_diameter[0]<=0.705")
    assert presets["cable-top"].compatible == ("nozzle_diameter[0]>=0.4 and "
                                               "nozzle_diameter[0]<=0.529")
    noz = load_printer(design.printer).nozzle_diameter_mm
    for p in presets.values():
        lo, hi = map(float, re.findall(r"[<>]=([\d.]+)", p.compatible))
        assert lo <= noz <= hi  # offered with printgen's own printer
    mk4 = load_printer("prusa-mk4").nozzle_diameter_mm
    lo = float(re.findall(r">=([\d.]+)", presets["net"].compatible)[0])
    assert mk4 < lo  # the 0.35 mm first layer is not offered for a 0.4 mm nozzle


def test_parts_whose_settings_differ_get_their_own_preset_names(design):
    """A cable with a wider eyelet band needs more perimeter loops: same section, style and
    material, so the same name, but other settings: each takes its part's name."""
    printer = load_printer(design.printer)
    wide = dataclasses.replace(design.cables[3], eyelet_outer_mm=8.0)
    d = dataclasses.replace(design, cables=(*design.cables[:3], wide))
    p = design_presets(d, printer)
    assert p["cable-right"].settings["print"]["perimeters"] != \
        p["cable-left"].settings["print"]["perimeters"]
    names = {k: v.names["print"] for k, v in p.items()}
    assert names["cable-right"] == names["cable-top"] + " - cable-right"
    assert names["cable-top"] == names["cable-bottom"] == names["cable-left"]  # equal: shared
    assert p["cable-right"].names["filament"] == p["cable-left"].names["filament"]  # shared
    cp = _bundle(prusa_bundle_text(list(p.values())))  # no duplicate section
    assert f"print:{names['cable-right']}" in cp.sections()


def test_flat_files_carry_the_preset_names(presets):
    net = presets["net"]
    whole = _flat(presets_ini_text(net))
    assert whole["print_settings_id"] == net.names["print"]
    assert whole["filament_settings_id"] == f'"{net.names["filament"]}"'  # a list: quoted
    assert whole["printer_settings_id"] == net.names["printer"]
    assert set(whole) - set(SETTINGS_IDS.values()) == set(net.merged())
    on_top = _flat(presets_ini_text(net, ("print", "filament")))
    assert "printer_settings_id" not in on_top
    groups = prusa_key_presets()
    assert {groups[k] for k in set(on_top) - set(SETTINGS_IDS.values())} == {"print",
                                                                             "filament"}


def test_the_3mf_records_the_preset_names(presets):
    trimesh = pytest.importorskip("trimesh")
    mesh = trimesh.creation.box((10.0, 10.0, 1.0))
    mesh.apply_translation((50.0, 50.0, 0.5))
    data = threemf_bytes([("net", mesh)], presets_ini_text(presets["net"]))
    with zipfile.ZipFile(io.BytesIO(data)) as z:
        config = z.read("Metadata/Slic3r_PE.config").decode()
    ids = dict(ln[2:].split(" = ", 1) for ln in config.splitlines() if "_settings_id" in ln)
    assert ids == {"print_settings_id": "printgen net TPE 0.6 x 0.95 mm (net-3pass)",
                   "filament_settings_id": '"printgen TPE 1.75 mm"',
                   "printer_settings_id": "printgen Generic 350 x 350 (0.5 mm nozzle)"}


def test_preset_keys_sit_in_the_presets_prusaslicer_puts_them_in():
    """PrusaSlicer removes a key from a preset of the wrong kind when it imports a bundle;
    its own vendor bundles show where each key goes."""
    require_tool("prusa-slicer")
    if not PRUSA_PROFILES.is_dir():
        _missing(f"{PRUSA_PROFILES} (prusa-slicer's vendor profiles)")
    seen: dict[str, set[str]] = {}
    for path in sorted(PRUSA_PROFILES.glob("*.ini")):
        kind = None
        for line in path.read_text("utf-8", errors="replace").splitlines():
            if line.startswith("["):
                m = re.match(r"\[(print|filament|printer):", line)
                kind = m.group(1) if m else None
            elif kind and "=" in line:
                seen.setdefault(line.split("=", 1)[0].strip(), set()).add(kind)
    groups = prusa_key_presets()
    checked = [k for k in groups if k in seen]
    assert len(checked) > 0.8 * len(groups)  # most keys appear in some vendor preset
    # elefant_foot_compensation appears in a few vendor printer sections too
    assert sorted(k for k in checked if groups[k] not in seen[k]) == []


# ----------------------------------------------------------------------------- slicing
def _missing(what: str) -> None:
    msg = f"{what} not found (bash scripts/setup.sh --with-slicers installs prusa-slicer)"
    if os.environ.get("PRINTGEN_REQUIRE_SLICERS") or os.environ.get("CI"):
        pytest.fail(msg)
    pytest.skip(msg)


def stock_printer_ini(bundle: Path, name: str) -> str:
    """A vendor printer preset flattened as PrusaSlicer does (each `inherits` parent in
    order, then the preset's own keys): the printer-only .ini a lab exports."""
    cp = configparser.RawConfigParser(strict=False, interpolation=None, delimiters=("=",),
                                      comment_prefixes=("#", ";"), inline_comment_prefixes=None)
    cp.optionxform = str  # type: ignore[assignment,method-assign]
    cp.read(bundle, encoding="utf-8")

    def flat(section: str) -> dict[str, str]:
        s = cp[section]
        out: dict[str, str] = {}
        for parent in (p.strip() for p in s.get("inherits", "").split(";")):
            if parent:
                out |= flat(f"printer:{parent}")
        return out | {k: v for k, v in s.items() if k != "inherits"}

    return "".join(f"{k} = {v}\n" for k, v in flat(f"printer:{name}").items())


def _part(design, name):
    """(kind, part, mesh placed on printgen's printer's bed as make's STL: the 351 mm cable
    turned to fit)."""
    pytest.importorskip("manifold3d")
    from printgen.parts.export import place_mesh
    from printgen.parts.geometry.solid import cable_solid, net_solid

    printer = load_printer(design.printer)
    if name == "net":
        return "net", design.net, place_mesh(net_solid(design.net), printer, name)[0]
    c = next(c for c in design.cables if f"cable-{c.name}" == name)
    return "cable", c, place_mesh(cable_solid(c), printer, name)[0]


def _slice(tmp_path, stl, *loads, extra=()):
    exe = require_tool("prusa-slicer")
    out = tmp_path / f"{stl.stem}.gcode"
    args = [exe, "--loglevel", "1", "--export-gcode"]
    for ini in loads:
        args += ["--load", str(ini)]
    r = subprocess.run([*args, *extra, "--output", str(out), str(stl)], capture_output=True,
                       text=True, timeout=SLICE_TIMEOUT_S, check=False)
    assert r.returncode == 0 and out.is_file(), (r.stdout + r.stderr)[-800:]
    return out


def _trailer(gcode: Path) -> dict[str, str]:
    return dict(ln[2:].split(" = ", 1) for ln in gcode.read_text().splitlines()
                if ln.startswith("; ") and " = " in ln)


@pytest.mark.slow
@pytest.mark.parametrize("printer_from", ["stock", "bundle"])
@pytest.mark.parametrize("part", ["net", "cable-top"])
def test_print_and_filament_presets_slice_on_top_of_a_printer_preset(
        design, presets, tmp_path, part, printer_from):
    """`prusa-slicer --load PRINTER.ini --load PART.prusa-print.ini` slices the 1:40 part, with
    the printer's machine settings and printgen's print and filament settings, and the
    G-code passes the shared checker. PRINTER: a stock vendor preset (its start G-code swapped
    for printgen's printer's: the vendor's purge line is a layer of its own to the checker;
    the untouched preset is sliced too), or the printer section of printgen's bundle."""
    check = require_shared("tools/gcode/check_gcode.py")
    kind, part_design, mesh = _part(design, part)
    stl = tmp_path / f"{part}.stl"
    mesh.export(stl)
    p = presets[part]
    on_top = tmp_path / f"{part}.prusa-print.ini"
    on_top.write_text(presets_ini_text(p, ("print", "filament")))
    printer = tmp_path / "printer.ini"
    extra: tuple[str, ...] = ()
    if printer_from == "stock":
        bundle = PRUSA_PROFILES / STOCK[0]
        if not bundle.is_file():
            _missing(str(bundle))
        printer.write_text(stock_printer_ini(bundle, STOCK[1]))
        stock = _flat(printer.read_text())
        untouched = _trailer(_slice(tmp_path, stl, printer, on_top))
        assert untouched["start_gcode"] == stock["start_gcode"]
        extra = ("--start-gcode", p.settings["printer"]["start_gcode"])
    else:
        cp = _bundle(prusa_bundle_text(list(presets.values())))
        printer.write_text("".join(f"{k} = {v}\n" for k, v in
                                   cp[f"printer:{p.names['printer']}"].items()))
    gcode = _slice(tmp_path, stl, printer, on_top, extra=extra)
    got = _trailer(gcode)
    machine = _flat(printer.read_text())
    for key in ("bed_shape", "nozzle_diameter", "gcode_flavor", "printer_model"):
        if key in machine:
            assert got[key] == machine[key], key  # the lab's printer stays
    for kind_ in ("print", "filament"):
        for key, value in p.settings[kind_].items():
            assert got[key] == value.replace("\n", "\\n"), key  # printgen's settings win
    assert got["print_settings_id"] == p.names["print"]
    sec = part_design.strand if kind == "net" else part_design.section
    mat = load_material(part_design.material)
    args = ["--auto", "--stl", str(stl), "--width", f"{sec.bead_width_mm:g}",
            "--area-model", "stadium", "--layers", str(len(sec.layer_heights_mm)),
            "--max-flow", f"{mat.print.max_volumetric_flow_mm3_per_s:g}"]
    if printer_from == "stock":
        args += ["--bed-margin", f"{STOCK_HOME_OUTSIDE_MM:g}"]
    r = subprocess.run(["python3", str(check), str(gcode), *args], capture_output=True,
                       text=True, timeout=SLICE_TIMEOUT_S, check=False)
    assert r.returncode == 0, r.stdout[-1500:]
    assert r.stdout.strip().splitlines()[-1].startswith("GCODE-CHECK OK")


@pytest.mark.slow
def test_prusaslicer_reads_the_preset_names_of_the_3mf(design, presets, tmp_path):
    exe = require_tool("prusa-slicer")
    _, _, mesh = _part(design, "cable-left")
    path = tmp_path / "cable-left.3mf"
    path.write_bytes(threemf_bytes([("cable-left", mesh)],
                                   presets_ini_text(presets["cable-left"])))
    out = tmp_path / "cable-left.gcode"
    r = subprocess.run([exe, "--loglevel", "1", "--export-gcode", "--output", str(out),
                        str(path)], capture_output=True, text=True, timeout=SLICE_TIMEOUT_S,
                       check=False)
    assert r.returncode == 0, r.stderr[-800:]
    got = _trailer(out)
    assert {k: got[k] for k in SETTINGS_IDS.values()} == presets["cable-left"].ids()


@pytest.mark.slow
@pytest.mark.parametrize("part", ["net", "cable-top"])
def test_prusaslicer_evaluates_the_nozzle_condition_of_each_print_preset(presets, tmp_path,
                                                                         part):
    """The GUI offers a print preset where its compatible_printers_condition holds; PrusaSlicer
    evaluates the same expression language in custom G-code, so a slice with the condition
    in the start G-code shows how it evaluates, nozzle by nozzle."""
    trimesh = pytest.importorskip("trimesh")
    cube = trimesh.creation.box((10.0, 10.0, 0.4))
    cube.apply_translation((100.0, 100.0, 0.2))
    stl = tmp_path / "cube.stl"
    cube.export(stl)
    cond = presets[part].compatible
    lo, hi = map(float, re.findall(r"[<>]=([\d.]+)", cond))
    for nozzle in (0.3, 0.4, 0.5, 0.6, 0.8):
        gcode = _slice(tmp_path, stl, extra=(
            "--nozzle-diameter", f"{nozzle:g}", "--layer-height", "0.2",
            "--first-layer-height", "0.2",
            "--start-gcode", f"{{if {cond}}};offered{{else}};not offered{{endif}}"))
        offered = ";offered\n" in gcode.read_text()
        assert offered == (lo <= nozzle <= hi), (cond, nozzle)


# ----------------------------------------------------------------------------- Cura
def _cura_tree(defs: Path) -> dict[str, dict]:
    out: dict[str, dict] = {}

    def walk(node: dict, category: str) -> None:
        for k, v in node.items():
            out[k] = {**v, "category": category}
            walk(v.get("children", {}), category)

    for name in ("fdmprinter.def.json", "fdmextruder.def.json"):
        for cat in json.loads((defs / name).read_text())["settings"].values():
            walk(cat.get("children", {}), cat["label"])
    return out


def _require_definitions() -> Path:
    defs = find_definitions()
    if defs is None:
        _missing("Cura's fdmprinter.def.json")
    assert defs is not None
    return defs


def _cable_settings(design):
    c = design.cables[0]
    return cura_settings("cable", c, load_printer(design.printer),
                         load_print_style(c.print_style), load_material(c.material))


def test_cura_profile_is_an_instance_container_cura_4_13_imports(design):
    """Checked against the `cura` package's own files: the version and setting_version of its
    quality containers, the definition, the empty quality's type, and every value against its
    setting's type, options and literal bounds."""
    defs = _require_definitions()
    res = defs.parent
    normal = configparser.ConfigParser(interpolation=None)
    normal.read(res / "quality" / "normal.inst.cfg")
    assert int(normal["general"]["version"]) == CURA_CONTAINER_VERSION
    assert int(normal["metadata"]["setting_version"]) == CURA_SETTING_VERSION
    assert (defs / f"{CURA_DEFINITION}.def.json").is_file()
    empty = next(res.parent.parent.parent.glob(
        "lib/python3/dist-packages/cura/Settings/cura_empty_instance_containers.py"), None)
    if empty is not None:  # the Python part of the cura package, when extracted
        assert f'"quality_type", "{CURA_QUALITY_TYPE}"' in empty.read_text()
    data = curaprofile_bytes("cable-top", _cable_settings(design))
    with zipfile.ZipFile(io.BytesIO(data)) as z:
        (entry,) = z.namelist()
        cfg = configparser.ConfigParser(interpolation=None)
        cfg.read_string(z.read(entry).decode("utf-8"))
    assert cfg["general"]["name"] == "cable-top"
    assert dict(cfg["metadata"]) == {"type": "quality_changes",
                                     "quality_type": CURA_QUALITY_TYPE,
                                     "setting_version": str(CURA_SETTING_VERSION)}
    tree = _cura_tree(defs)
    values = dict(cfg["values"])
    assert len(values) == len(cura_profile_keys())
    for key, value in values.items():
        d = tree[key]
        assert d["category"] not in ("Machine", "Command Line Settings"), key
        if d["type"] == "bool":
            assert value in ("True", "False"), key
        elif d["type"] == "enum":
            assert value in d["options"], key
        elif d["type"] in ("float", "int"):
            x = float(value) if d["type"] == "float" else int(value)
            lo, hi = d.get("minimum_value"), d.get("maximum_value")  # a number or a formula
            assert not isinstance(lo, (int, float)) or x >= lo, (key, value, lo)
            assert not isinstance(hi, (int, float)) or x <= hi, (key, value, hi)


# CuraEngine settings that are the printer's in Cura's GUI though not in its Machine category
PRINTER_OWN = {"material_diameter", "relative_extrusion"}


def test_cura_keys_table_matches_the_definitions(design):
    defs = _require_definitions()
    tree = _cura_tree(defs)
    for key, (category, label, unit) in cura_profile_keys().items():
        d = tree[key]
        assert (category, label, unit) == (d["category"], d["label"], d.get("unit", "")), key
    # every CuraEngine setting left out of the profile is the printer's
    left_out = set(_cable_settings(design)) - set(cura_profile_keys())
    assert {k for k in left_out if k not in PRINTER_OWN
            and tree[k]["category"] not in ("Machine", "Command Line Settings")} == set()


def test_cura_settings_table_reads_as_one_header_row(design):
    s = _cable_settings(design)
    rows = list(csv.DictReader(io.StringIO(cura_table_csv(s))))
    assert tuple(rows[0]) == TABLE_COLUMNS
    table = {r["setting"]: r for r in rows}
    assert table["layer_height"]["value"] == "0.3" and table["layer_height"]["unit"] == "mm"
    assert table["layer_height"]["label"] == "Layer Height"
    assert table["material_print_temperature"]["value"] == "240"
    assert "machine_width" not in table and "material_diameter" not in table  # the printer's
    assert table["cool_fan_enabled"]["value"] == "True"


def test_cura_profile_is_reproducible(design):
    s = _cable_settings(design)
    assert curaprofile_bytes("cable-top", s) == curaprofile_bytes("cable-top", s)


# ----------------------------------------------------------------------------- every pair
LIMIT = re.compile(r"(exceeds|is below|does not fit)[^;]*?\d+(\.\d+)? mm")


def _pair_outcome(base: Path, printer: str, style: str, tmp_path: Path) -> str:
    """'prints' when every part of the example at 1:40 passes printgen's checks and gets its
    direct toolpath, PrusaSlicer presets and (cables) Cura settings; else the refusal."""
    from printgen.inputs.prototype import load_prototype
    from printgen.parts.gcode import cable_toolpath, net_toolpath
    from printgen.parts.geometry.attach import attachment_for
    from printgen.scaling.plan import make_design
    from printgen.scaling.selection import select
    from printgen.scaling.similitude import scale_targets

    pr = load_printer(printer)
    component = load_print_style(style).component
    other = "cable" if component == "net" else "net"
    # the other part keeps the style made for this printer's nozzle, as `make --printer` does
    edit = {("model", "printer"): printer, ("model", f"{component}_print"): style}
    own = pr.cable_print if other == "cable" else pr.net_print
    if own:
        edit[("model", f"{other}_print")] = own
    p = load_prototype(write_variant(tmp_path, edit, base=base))
    try:
        t = scale_targets(p, 40)
        d = make_design(p, t, select(p, t))
        att = (attachment_for(d, hole_compensation_mm=pr.hole_compensation_mm)
               if d.cables else None)
        net_toolpath(d.net, pr, load_print_style(d.net.print_style),
                     load_material(d.net.material), attachment=att)
        for c in d.cables:
            cs = load_print_style(c.print_style)
            cable_toolpath(c, pr, cs, load_material(c.material))
            cura_settings("cable", c, pr, cs, load_material(c.material))
        design_presets(d, pr)
    except (PrintabilityError, DesignError) as e:  # refused: the message must name the limit
        return str(e)
    return "prints"


@pytest.mark.slow  # 16 selections and designs: a few seconds
def test_every_bundled_printer_and_print_style_prints_the_examples_or_names_the_limit(
        tmp_path):
    outcomes = {(ex.stem, printer, style): _pair_outcome(ex, printer, style, tmp_path)
                for ex in (REALISTIC, SIMPLE) for printer in list_profiles("printers")
                for style in list_profiles("prints")}
    assert len(outcomes) >= 16  # 2 examples x 2 printers x 4 styles at least
    for key, outcome in outcomes.items():
        assert outcome == "prints" or LIMIT.search(outcome), (key, outcome)
    for ex in (REALISTIC, SIMPLE):  # each example prints on some bundled pair
        assert any(o == "prints" for (e, _, _), o in outcomes.items() if e == ex.stem)
    # the 0.4 mm-nozzle printer: its own net style lays 0.25 mm layers, and then the bed
    # (250 x 210 mm) is the limit for both 1:40 nets (335 and 300 mm wide)
    for ex in (REALISTIC, SIMPLE):
        assert "does not fit the usable 240 x 200 mm" in outcomes[
            (ex.stem, "prusa-mk4", "net-3pass-04")]
        assert "layer height 0.35 mm exceeds 0.3 mm" in outcomes[
            (ex.stem, "prusa-mk4", "net-3pass")]
    assert all(outcomes[(ex.stem, "generic-350", s)] == "prints"
               for ex in (REALISTIC, SIMPLE) for s in list_profiles("prints"))


def test_presets_of_a_part_the_printer_cannot_print_are_not_made(design):
    mk4 = load_printer("prusa-mk4")
    net = design.net
    with pytest.raises(PrintabilityError, match="layer height 0.35 mm exceeds 0.3 mm"):
        prusa_presets("net", net, mk4, load_print_style(net.print_style),
                      load_material(net.material))


# ----------------------------------------------------------------------------- make's files
def test_make_writes_the_presets_and_names_them_in_the_3mfs(made_1_40):
    """Each part's print+filament .ini, the config bundle, and for the cables the Cura
    profile and table: listed in the manifest; every 3MF names presets of the bundle."""
    from printgen.outputs import folder_files

    ctx, out = made_1_40
    names = folder_files(out)
    manifest = json.loads((out / "manifest.json").read_text())["files"]
    parts = ["net"] + [f"cable-{c.name}" for c in ctx.design.cables]
    wanted = ["prusaslicer-bundle.ini", *(f"{p}.prusa-print.ini" for p in parts),
              *(f"{p}.{ext}" for p in parts[1:]
                for ext in ("curaprofile", "cura-settings.csv"))]
    for name in wanted:
        assert name in names and name in manifest, name
    cp = _bundle((out / "prusaslicer-bundle.ini").read_text())
    for threemf in [f"{p}.3mf" for p in parts] + ["cables-plate.3mf"]:
        with zipfile.ZipFile(out / threemf) as z:
            config = z.read("Metadata/Slic3r_PE.config").decode()
        ids = dict(ln[2:].split(" = ", 1) for ln in config.splitlines()
                   if "_settings_id = " in ln)
        for kind, key in SETTINGS_IDS.items():
            assert f"{kind}:{ids[key].strip(chr(34))}" in cp.sections(), (threemf, kind)
    guide = (Path(__file__).resolve().parents[1] / "docs" / "user-guide.md").read_text()
    for pattern in ("prusaslicer-bundle.ini", "PART.prusa-print.ini", "PART.prusa.ini",
                    "cable-NAME.curaprofile", "cable-NAME.cura-settings.csv"):
        assert f"`{pattern}`" in guide, pattern  # the user guide says what each file is for
    for p in parts:  # the flat print+filament file holds no printer key
        groups = prusa_key_presets()
        flat = _flat((out / f"{p}.prusa-print.ini").read_text())
        assert {groups[k] for k in flat if k in groups} == {"print", "filament"}
