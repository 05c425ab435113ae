"""PrusaSlicer 2.5 `.ini` profiles for a net or a cable, following slicers.md.

One bead per strand in Arachne needs `min_bead_width < strand < extrusion width`: the
extrusion widths are `slicer_width_factor` (about 1.15) x the strand's bead width (for an odd
number of beads across; an even number is whole perimeter loops at the bead width: with 1.15 x
a two-bead TPU strand had only 71-87 % of its path within 15 % of the bead section), the
minimum bead `slicer_min_bead_factor` (about 0.85) x it, and the first-layer width equals the
others. E is relative with `G92 E0` at each layer; the material's volumetric flow limit caps
the speeds. Only keys in `prusa_keys.txt` are written (PrusaSlicer ignores unknown keys).
"""

from __future__ import annotations

import re
from functools import cache
from importlib import resources
from pathlib import Path

from printgen.errors import PrintabilityError, ProfileError
from printgen.inputs.materials import Material
from printgen.inputs.printers import Printer, PrintStyle
from printgen.outputs import write_text
from printgen.parts.gcode.toolpath import check_part, part_section, wall_loops
from printgen.parts.gcode.writer import placeholder_values
from printgen.scaling.record import CableDesign, NetDesign

FLAVORS = {"marlin2": "marlin2", "marlin": "marlin", "reprap": "reprapfirmware",
           "klipper": "marlin2"}
LAYER_TOL_MM = 1e-6  # layers above the first must all be this close to one height
SKIRT_DISTANCE_MM = 3.0
RETRACT_MIN_TRAVEL_MM = 3.0  # PrusaSlicer retract_before_travel
_PLACEHOLDER = re.compile(r"\{(\w+)\}")


@cache
def allowed_prusa_keys() -> frozenset[str]:
    """Keys printgen may write into a PrusaSlicer .ini (from prusa_keys.txt)."""
    text = resources.files("printgen.parts.slicer").joinpath("prusa_keys.txt").read_text("utf-8")
    return frozenset(ln.strip() for ln in text.splitlines()
                     if ln.strip() and not ln.startswith("#"))


def prusa_settings(part_kind: str, design_part: NetDesign | CableDesign, printer: Printer,
                   style: PrintStyle, material: Material) -> dict[str, str]:
    """PrusaSlicer settings (key -> value text) for one part; raises before anything is made.

    part_kind : 'net' or 'cable'; design_part : the NetDesign or CableDesign.
    """
    check_part(part_kind, design_part, printer, style)
    sec = part_section(part_kind, design_part)
    heights = sec.layer_heights_mm
    rest = set(heights[1:])
    if rest and max(rest) - min(rest) > LAYER_TOL_MM:
        raise PrintabilityError(
            f"{part_kind}: layer heights {heights} mm vary above the first layer; PrusaSlicer "
            "prints one layer_height: use equal heights after the first")
    s = {**_printer(printer, material), **_filament(printer, material),
         **_layers(part_kind, design_part, style, heights), **_speeds(printer, material)}
    unknown = sorted(set(s) - allowed_prusa_keys())
    if unknown:
        raise ProfileError(f"PrusaSlicer keys {unknown} are not in prusa_keys.txt; add them "
                           "after checking `prusa-slicer --help-fff`")
    return s


# PrusaSlicer 2.5 lays short moves up to 5.3 % over its own max_volumetric_speed (a TPE
# coupon's eyelet: 1.58 mm3/s at a 1.5 limit); the cap it gets is this x the limit
PRUSA_FLOW_MARGIN = 0.95


def _filament(printer: Printer, material: Material) -> dict[str, str]:
    p = material.print
    flow = f"{PRUSA_FLOW_MARGIN * p.max_volumetric_flow_mm3_per_s:.4g}"
    return {
        "filament_type": p.filament_type, "filament_diameter": f"{printer.filament_diameter_mm:g}",
        "filament_density": f"{material.density / 1000:g}", "extrusion_multiplier": "1",
        "temperature": f"{p.nozzle_temperature_deg_c:g}",
        "first_layer_temperature": f"{p.first_layer_nozzle_temperature_deg_c:g}",
        "bed_temperature": f"{p.bed_temperature_deg_c:g}",
        "first_layer_bed_temperature": f"{p.first_layer_bed_temperature_deg_c:g}",
        "filament_max_volumetric_speed": flow, "max_volumetric_speed": flow,
        "cooling": "1", "fan_always_on": "1", "min_fan_speed": f"{p.fan_min_percent:g}",
        "max_fan_speed": f"{p.fan_max_percent:g}", "bridge_fan_speed": "100",
        "disable_fan_first_layers": "1", "slowdown_below_layer_time": "5",
        "min_print_speed": "2",
        "retract_length": f"{p.retract_length_mm:g}",
        "retract_speed": f"{p.retract_speed_mm_per_s:g}",
        "deretract_speed": f"{p.retract_speed_mm_per_s:g}",
    }


def _layers(part_kind: str, part: NetDesign | CableDesign, style: PrintStyle,
            heights: tuple[float, ...]) -> dict[str, str]:
    """Layer heights and Arachne widths: min_bead < strand bead < extrusion width."""
    sec = part_section(part_kind, part)
    bead = sec.bead_width_mm
    # an odd bead count leaves one medial bead, which needs the wider extrusion; an even one
    # is filled by whole loops at the bead width (wider, 2-bead strands fail)
    factor = style.slicer_width_factor if sec.beads_across % 2 else 1.0
    width = f"{factor * bead:.4g}"
    s = {
        "layer_height": f"{(heights[1] if len(heights) > 1 else heights[0]):g}",
        "first_layer_height": f"{heights[0]:g}",
        "perimeters": str(wall_loops(part_kind, part)),
        "perimeter_generator": "arachne", "thin_walls": "1",
        "min_bead_width": f"{style.slicer_min_bead_factor * bead:.4g}", "min_feature_size": "25%",
        "fill_density": "0%", "top_solid_layers": "0", "bottom_solid_layers": "0",
        "gap_fill_enabled": "0", "extra_perimeters": "0", "ensure_vertical_shell_thickness": "0",
        "overhangs": "0", "skirts": "1", "skirt_distance": f"{SKIRT_DISTANCE_MM:g}",
        "brim_width": "0", "avoid_crossing_perimeters": "0", "seam_position": "aligned",
    }
    # first_layer_extrusion_width overrides every width on layer 1 (slicers.md pitfall 3)
    for k in ("extrusion_width", "perimeter_extrusion_width", "external_perimeter_extrusion_width",
              "first_layer_extrusion_width", "infill_extrusion_width",
              "solid_infill_extrusion_width", "top_infill_extrusion_width"):
        s[k] = width
    return s


def _speeds(printer: Printer, material: Material) -> dict[str, str]:
    v, v0 = material.print.print_speed_mm_per_s, material.print.first_layer_speed_mm_per_s
    return {"perimeter_speed": f"{v:g}", "external_perimeter_speed": f"{v:g}",
            "small_perimeter_speed": f"{v:g}", "first_layer_speed": f"{v0:g}",
            "gap_fill_speed": f"{v0:g}", "travel_speed": f"{printer.travel_speed_mm_per_s:g}"}


def _printer(printer: Printer, material: Material) -> dict[str, str]:
    bx, by = printer.bed_x_mm, printer.bed_y_mm
    vals = placeholder_values(printer, material)
    return {
        "printer_technology": "FFF", "gcode_flavor": FLAVORS[printer.gcode_flavor],
        "bed_shape": f"0x0,{bx:g}x0,{bx:g}x{by:g},0x{by:g}",
        "max_print_height": f"{printer.max_height_mm:g}",
        "nozzle_diameter": f"{printer.nozzle_diameter_mm:g}",
        "use_relative_e_distances": "1", "layer_gcode": "G92 E0",
        "gcode_comments": "0", "gcode_label_objects": "1",
        "start_gcode": _prusa_placeholders(printer.start_gcode, vals, f"{printer.key} start_gcode"),
        "end_gcode": _prusa_placeholders(printer.end_gcode, vals, f"{printer.key} end_gcode"),
        "retract_before_travel": f"{RETRACT_MIN_TRAVEL_MM:g}", "retract_lift": "0", "wipe": "0",
    }


def _prusa_placeholders(text: str, values: dict[str, float], where: str) -> str:
    """printgen's {name} -> PrusaSlicer's [name]; unknown names are errors."""
    def sub(m: re.Match[str]) -> str:
        if m.group(1) not in values:
            raise ProfileError(f"printer {where}: unknown placeholder {{{m.group(1)}}}; "
                               f"allowed: {', '.join(sorted(values))}")
        return f"[{m.group(1)}]"
    return _PLACEHOLDER.sub(sub, text)


def prusa_ini_text(part_kind: str, design_part: NetDesign | CableDesign, printer: Printer,
                   style: PrintStyle, material: Material) -> str:
    """The .ini text (flat `key = value`, newlines in values as `\\n`)."""
    s = prusa_settings(part_kind, design_part, printer, style, material)
    name = getattr(design_part, "name", "")
    head = [f"# printgen: PrusaSlicer 2.5 profile for the {part_kind} {name}".rstrip(),
            f"# printer {printer.key}, print style {style.key}, material {material.key}"]
    body = [f"{k} = {v.replace(chr(10), chr(92) + 'n')}" for k, v in sorted(s.items())]
    return "\n".join(head + body) + "\n"


def write_prusa_ini(path: str | Path, part_kind: str, design_part: NetDesign | CableDesign,
                    printer: Printer, style: PrintStyle, material: Material) -> Path:
    """Write the .ini atomically; a bad design raises before the file is touched."""
    return write_text(path, prusa_ini_text(part_kind, design_part, printer, style, material))
