"""CuraEngine 4.13 settings for a cable (Cura cannot print the net as single beads:
it has no Arachne, see slicers.md section 3).

CuraEngine's CLI does not evaluate fdmprinter.def.json formulas, so every derived setting is
given explicitly, and extruder settings (material_diameter above all) must be passed again
after `-e0` (`cura_engine_args` does both).

For Cura's GUI the same settings, less the printer's (the Machine settings, the filament
diameter, relative extrusion and the CLI-only ones), go in a `.curaprofile` (Preferences >
Profiles > Import) and a settings table to type in. A .curaprofile is a zip of Cura
instance containers; Cura 4.13's importer (CuraContainerRegistry.importProfile) takes one
global `quality_changes` container, moves its per-extruder settings to the first extruder
and re-targets its definition to the active printer's. Its quality_type is Cura's empty
quality, "not_supported": the only type every printer accepts and always shows
(MachineNode.getQualityChangesGroups); the profile sets every setting it needs.
"""

from __future__ import annotations

import csv
import io
import os
import zipfile
from functools import cache
from importlib import resources
from pathlib import Path

from printgen.errors import PrintabilityError, ProfileError
from printgen.inputs.materials import Material
from printgen.inputs.printers import Printer, PrintStyle
from printgen.outputs import write_text
from printgen.parts.gcode.toolpath import check_part, part_section, wall_loops
from printgen.parts.gcode.writer import fill_placeholders, placeholder_values
from printgen.scaling.record import CableDesign, NetDesign

DEFINITION_DIRS = ("/usr/share/cura/resources/definitions",
                   "/opt/cura-pkg/usr/share/cura/resources/definitions")
LAYER_TOL_MM = 1e-6  # layers above the first must all be this close to one height
SKIRT_GAP_MM = 3.0
LINE_WIDTH_KEYS = ("line_width", "wall_line_width", "wall_line_width_0", "wall_line_width_x",
                   "skin_line_width", "infill_line_width", "skirt_brim_line_width")
SPEED_KEYS = ("speed_print", "speed_wall", "speed_wall_0", "speed_wall_x", "speed_infill",
              "speed_topbottom")


def cura_settings(part_kind: str, design_part: NetDesign | CableDesign, printer: Printer,
                  style: PrintStyle, material: Material) -> dict[str, str]:
    """CuraEngine settings (key -> value text) for a cable: one wall loop per 2 beads."""
    if part_kind != "cable":
        raise PrintabilityError(
            "CuraEngine 4.13 cannot slice the diamond net into one bead per strand (it has no "
            "Arachne wall generator): use the PrusaSlicer profile or printgen's direct G-code")
    check_part(part_kind, design_part, printer, style)
    sec = part_section(part_kind, design_part)
    heights = sec.layer_heights_mm
    rest = set(heights[1:])
    if rest and max(rest) - min(rest) > LAYER_TOL_MM:
        raise PrintabilityError(f"cable: layer heights {heights} mm vary above the first layer; "
                                "Cura prints one layer_height: use equal heights after the first")
    p = material.print
    w = style.slicer_width_factor * sec.bead_width_mm
    walls = wall_loops(part_kind, design_part)
    # the volumetric limit caps the speed (Cura has no max_volumetric_speed)
    v = min(p.print_speed_mm_per_s, p.max_volumetric_flow_mm3_per_s / (w * max(heights)))
    v0 = min(p.first_layer_speed_mm_per_s, p.max_volumetric_flow_mm3_per_s / (w * heights[0]))
    s = {**_machine(printer, material), **_layers(heights, w, walls),
         **_material(material), **_speeds(printer, v, v0)}
    return s


def _machine(printer: Printer, material: Material) -> dict[str, str]:
    vals = placeholder_values(printer, material)
    return {
        "machine_width": f"{printer.bed_x_mm:g}", "machine_depth": f"{printer.bed_y_mm:g}",
        "machine_height": f"{printer.max_height_mm:g}", "machine_heated_bed": "true",
        "machine_center_is_zero": "false", "machine_gcode_flavor": "RepRap (Marlin/Sprinter)",
        "machine_start_gcode": fill_placeholders(printer.start_gcode, vals,
                                                 where=f"printer {printer.key} start_gcode"),
        "machine_end_gcode": fill_placeholders(printer.end_gcode, vals,
                                               where=f"printer {printer.key} end_gcode"),
        "relative_extrusion": "true", "center_object": "true",
        "machine_nozzle_size": f"{printer.nozzle_diameter_mm:g}",
        "material_diameter": f"{printer.filament_diameter_mm:g}", "material_flow": "100",
        "adhesion_type": "skirt", "skirt_line_count": "1", "skirt_gap": f"{SKIRT_GAP_MM:g}",
    }


def _layers(heights: tuple[float, ...], w: float, walls: int) -> dict[str, str]:
    return {
        "layer_height": f"{(heights[1] if len(heights) > 1 else heights[0]):g}",
        "layer_height_0": f"{heights[0]:g}",
        **{k: f"{w:.4g}" for k in LINE_WIDTH_KEYS},
        "initial_layer_line_width_factor": "100",
        "wall_line_count": str(walls), "wall_thickness": f"{2 * walls * w:.4g}",
        "infill_sparse_density": "0", "top_layers": "0", "bottom_layers": "0",
        "top_bottom_thickness": "0", "fill_outline_gaps": "true", "fill_perimeter_gaps": "nowhere",
        "filter_out_tiny_gaps": "false",
    }


def _material(material: Material) -> dict[str, str]:
    p = material.print
    return {
        "material_print_temperature": f"{p.nozzle_temperature_deg_c:g}",
        "material_print_temperature_layer_0": f"{p.first_layer_nozzle_temperature_deg_c:g}",
        "material_initial_print_temperature": f"{p.nozzle_temperature_deg_c:g}",
        "material_final_print_temperature": f"{p.nozzle_temperature_deg_c:g}",
        "material_bed_temperature": f"{p.bed_temperature_deg_c:g}",
        "material_bed_temperature_layer_0": f"{p.first_layer_bed_temperature_deg_c:g}",
        "cool_fan_enabled": "true", "cool_fan_speed": f"{p.fan_min_percent:g}",
        "cool_fan_speed_min": f"{p.fan_min_percent:g}",
        "cool_fan_speed_max": f"{p.fan_max_percent:g}", "cool_fan_full_layer": "2",
        "cool_min_layer_time": "5",
        "retraction_enable": "true", "retraction_amount": f"{p.retract_length_mm:g}",
        "retraction_speed": f"{p.retract_speed_mm_per_s:g}",
        "retraction_retract_speed": f"{p.retract_speed_mm_per_s:g}",
        "retraction_prime_speed": f"{p.retract_speed_mm_per_s:g}",
    }


def _speeds(printer: Printer, v: float, v0: float) -> dict[str, str]:
    return {
        **{k: f"{v:.4g}" for k in SPEED_KEYS},
        "speed_layer_0": f"{v0:.4g}", "speed_print_layer_0": f"{v0:.4g}",
        "skirt_brim_speed": f"{v0:.4g}",
        "speed_travel": f"{printer.travel_speed_mm_per_s:g}",
        "speed_travel_layer_0": f"{printer.travel_speed_mm_per_s / 2:g}",
    }


def cura_cfg_text(part_kind: str, design_part: NetDesign | CableDesign, printer: Printer,
                  style: PrintStyle, material: Material) -> str:
    """Settings as `key=value` lines (newlines in values as `\\n`), the slice_check_cura format."""
    s = cura_settings(part_kind, design_part, printer, style, material)
    head = [f"# printgen: CuraEngine 4.13 settings for the cable {design_part.name}",
            f"# printer {printer.key}, print style {style.key}, material {material.key}"]
    return "\n".join(head + [f"{k}={v.replace(chr(10), chr(92) + 'n')}"
                             for k, v in s.items()]) + "\n"


def write_cura_cfg(path: str | Path, part_kind: str, design_part: NetDesign | CableDesign,
                   printer: Printer, style: PrintStyle, material: Material) -> Path:
    """Write the settings file atomically; a bad design raises before the file is touched."""
    return write_text(path, cura_cfg_text(part_kind, design_part, printer, style, material))


def find_definitions() -> Path | None:
    """Folder holding fdmprinter.def.json ($CURA_DEFS first), or None."""
    for d in (os.environ.get("CURA_DEFS", ""), *DEFINITION_DIRS):
        if d and (Path(d) / "fdmprinter.def.json").is_file():
            return Path(d)
    return None


def cura_engine_args(settings: dict[str, str], stl: str | Path, out: str | Path,
                     definitions: str | Path) -> list[str]:
    """argv for `CuraEngine slice` with every setting given globally and again after -e0.

    Run it with CURA_ENGINE_SEARCH_PATH = definitions:<definitions>/../extruders.
    """
    s = [a for k, v in settings.items() for a in ("-s", f"{k}={v}")]
    return ["CuraEngine", "slice", "-v", "-j", str(Path(definitions) / "fdmprinter.def.json"),
            *s, "-e0", *s, "-l", str(stl), "-o", str(out)]


# Cura 4.13's formats (its resources/quality/*.inst.cfg; CuraApplication.SettingVersion)
CURA_CONTAINER_VERSION = 4
CURA_SETTING_VERSION = 19
CURA_QUALITY_TYPE = "not_supported"  # Cura's empty quality: importable on every printer
CURA_DEFINITION = "fdmprinter"  # the importer re-targets it to the active printer's
ZIP_TIME = (2020, 1, 1, 0, 0, 0)  # fixed timestamp: reproducible archives
TABLE_COLUMNS = ("setting", "category", "label", "value", "unit")


@cache
def cura_profile_keys() -> dict[str, tuple[str, str, str]]:
    """Setting -> (category, label, unit) of the settings a Cura profile carries (from
    cura_keys.tsv, in Cura's order of the file)."""
    text = resources.files("printgen.parts.slicer").joinpath("cura_keys.tsv").read_text("utf-8")
    rows = [ln.split("\t") for ln in text.splitlines() if ln and not ln.startswith("#")]
    return {r[0]: (r[1], r[2], r[3]) for r in rows}


def cura_profile_settings(settings: dict[str, str]) -> dict[str, str]:
    """The settings of a GUI profile: those listed in cura_keys.tsv (every other one is the
    printer's), switches written as Cura's own files write them (True / False)."""
    keys = cura_profile_keys()
    return {k: {"true": "True", "false": "False"}.get(v, v)
            for k, v in settings.items() if k in keys}


def curaprofile_bytes(name: str, settings: dict[str, str]) -> bytes:
    """A .curaprofile (zip of one global quality_changes container) named `name`."""
    values = cura_profile_settings(settings)
    if "\n" in name or not name.strip():
        raise ProfileError(f"Cura profile name {name!r} must be one non-empty line")
    text = "\n".join([
        "[general]", f"version = {CURA_CONTAINER_VERSION}", f"name = {name}",
        f"definition = {CURA_DEFINITION}", "", "[metadata]", "type = quality_changes",
        f"quality_type = {CURA_QUALITY_TYPE}", f"setting_version = {CURA_SETTING_VERSION}", "",
        "[values]", *(f"{k} = {v}" for k, v in values.items())]) + "\n"
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
        entry = "".join(c if c.isalnum() else "_" for c in name.lower())
        z.writestr(zipfile.ZipInfo(entry, ZIP_TIME), text)
    return buf.getvalue()


def cura_table_csv(settings: dict[str, str]) -> str:
    """The profile's settings as a table to type into Cura (setting, category, label, value,
    unit), one header row."""
    keys = cura_profile_keys()
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(TABLE_COLUMNS)
    w.writerows((k, *keys[k][:2], v, keys[k][2])
                for k, v in cura_profile_settings(settings).items())
    return buf.getvalue()
