"""PrusaSlicer 2.5 `.ini` profiles for a net or a cable, following slicers.md.

One bead per strand in Arachne needs `min_bead_width < strand < extrusion width`: the
extrusion widths are `slicer_width_factor` (about 1.15) x the strand's bead width (for an odd
number of beads across; an even number is whole perimeter loops at the bead width: with 1.15 x
a two-bead TPU strand had only 71-87 % of its path within 15 % of the bead section), the
minimum bead `slicer_min_bead_factor` (about 0.85) x it, and the first-layer width equals the
others. E is relative with `G92 E0` at each layer; the material's volumetric flow limit caps
the speeds. Only keys in `prusa_keys.txt` are written (PrusaSlicer ignores unknown keys).

The settings are also split as PrusaSlicer's presets (`prusa_presets`): a named print and
filament preset that sit on top of the lab's own printer preset (no printer key in them),
and a printer preset for printgen's printer. `prusa_bundle_text` writes them as a config
bundle (GUI: File > Import > Import Config Bundle); `prusa_on_top_text` as a flat file
loaded after a printer config (`prusa-slicer --load printer.ini --load part.ini`).
"""

from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass
from functools import cache
from importlib import resources
from pathlib import Path

from printgen.errors import PrintabilityError, ProfileError
from printgen.inputs.materials import Material, load_material
from printgen.inputs.printers import Printer, PrintStyle, load_print_style, nozzle_range_mm
from printgen.outputs import write_text
from printgen.parts.gcode.toolpath import check_part, part_section, wall_loops
from printgen.parts.gcode.writer import placeholder_values
from printgen.scaling.record import CableDesign, Design, NetDesign

FLAVORS = {"marlin2": "marlin2", "marlin": "marlin", "reprap": "reprapfirmware",
           "klipper": "marlin2"}
LAYER_TOL_MM = 1e-6  # layers above the first must all be this close to one height
SKIRT_DISTANCE_MM = 3.0
RETRACT_MIN_TRAVEL_MM = 3.0  # PrusaSlicer retract_before_travel
_PLACEHOLDER = re.compile(r"\{(\w+)\}")


PRESET_KINDS = ("print", "filament", "printer")  # PrusaSlicer's preset types, bundle order


@cache
def prusa_key_presets() -> dict[str, str]:
    """Key -> the preset it belongs to ('print', 'filament' or 'printer'), from
    prusa_keys.txt."""
    text = resources.files("printgen.parts.slicer").joinpath("prusa_keys.txt").read_text("utf-8")
    out = {}
    for ln in text.splitlines():
        if ln.strip() and not ln.startswith("#"):
            key, kind = ln.split()
            if kind not in PRESET_KINDS:
                raise ProfileError(f"prusa_keys.txt: {key} belongs to {kind!r}; expected one of "
                                   f"{', '.join(PRESET_KINDS)}")
            out[key] = kind
    return out


def allowed_prusa_keys() -> frozenset[str]:
    """Keys printgen may write into a PrusaSlicer .ini (from prusa_keys.txt)."""
    return frozenset(prusa_key_presets())


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
        # the material's retraction as the filament's overrides of the printer's: it goes
        # with the filament preset onto any printer preset
        "filament_retract_length": f"{p.retract_length_mm:g}",
        "filament_retract_speed": f"{p.retract_speed_mm_per_s:g}",
        "filament_deretract_speed": f"{p.retract_speed_mm_per_s:g}",
        "filament_retract_before_travel": f"{RETRACT_MIN_TRAVEL_MM:g}",
        "filament_retract_lift": "0", "filament_wipe": "0",
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
        # PrusaSlicer's defaults, written so that a print preset loaded over a lab's whole
        # config does not keep settings that reshape the strands (a vendor preset's 0.2 mm
        # elephant-foot compensation narrows every first-layer strand)
        "elefant_foot_compensation": "0", "xy_size_compensation": "0", "support_material": "0",
        "raft_layers": "0", "spiral_vase": "0", "ironing": "0", "fuzzy_skin": "none",
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


BUNDLE_FILE = "prusaslicer-bundle.ini"  # the run's config bundle, beside the parts
# the key naming each preset in a config (the 3MF's Metadata/Slic3r_PE.config, an .ini)
SETTINGS_IDS = {"print": "print_settings_id", "filament": "filament_settings_id",
                "printer": "printer_settings_id"}
NAME_TROUBLE = re.compile(r'[\[\];"\\\x00-\x1f]')  # would break a bundle section or an id list
CONDITION_DIGITS = 3  # nozzle bounds in mm, rounded inwards to this many decimals


@dataclass(frozen=True)
class PrusaPresets:
    """One part's settings as PrusaSlicer presets: for each of PRESET_KINDS its name and its
    settings (key -> value text), the print preset's compatible_printers_condition (the
    nozzles its widths and layers are made for), and the .ini's header lines."""

    part: str
    names: dict[str, str]
    settings: dict[str, dict[str, str]]
    compatible: str
    header: tuple[str, ...]

    def merged(self) -> dict[str, str]:
        """Every setting of the three presets (the whole config)."""
        return {k: v for kind in PRESET_KINDS for k, v in self.settings[kind].items()}

    def ids(self, kinds: tuple[str, ...] = PRESET_KINDS) -> dict[str, str]:
        """The *_settings_id entries naming the presets (filament_settings_id is a list: quoted)."""
        return {SETTINGS_IDS[k]: f'"{self.names[k]}"' if k == "filament" else self.names[k]
                for k in kinds}


def preset_name(text: str) -> str:
    """A preset name: characters that break a bundle section or an id list dropped."""
    return " ".join(NAME_TROUBLE.sub("", text).split())


def prusa_presets(part_kind: str, design_part: NetDesign | CableDesign, printer: Printer,
                  style: PrintStyle, material: Material) -> PrusaPresets:
    """`prusa_settings` split as PrusaSlicer's print, filament and printer presets, named
    after what sets them (the part's section, style and material; the material and filament
    diameter; printgen's printer)."""
    s = prusa_settings(part_kind, design_part, printer, style, material)
    groups = prusa_key_presets()
    settings = {kind: {k: v for k, v in s.items() if groups[k] == kind} for kind in PRESET_KINDS}
    sec = part_section(part_kind, design_part)
    names = {
        "print": preset_name(f"printgen {part_kind} {material.name} {sec.width_mm:g} x "
                             f"{sec.thickness_mm:g} mm ({style.key})"),
        "filament": preset_name(f"printgen {material.name} "
                                f"{printer.filament_diameter_mm:g} mm"),
        "printer": preset_name(f"printgen {printer.name}")}
    lo, hi = nozzle_range_mm(printer, sec.bead_width_mm, sec.layer_heights_mm)
    scale = 10 ** CONDITION_DIGITS
    lo, hi = math.ceil(lo * scale - 1e-6) / scale, math.floor(hi * scale + 1e-6) / scale
    compatible = f"nozzle_diameter[0]>={lo:g} and nozzle_diameter[0]<={hi:g}"
    name = getattr(design_part, "name", "")
    header = (f"# printgen: PrusaSlicer 2.5 profile for the {part_kind} {name}".rstrip(),
              f"# printer {printer.key}, print style {style.key}, material {material.key}")
    part = part_kind if part_kind == "net" else f"cable-{name}"
    return PrusaPresets(part, names, settings, compatible, header)


def unique_preset_names(presets: list[PrusaPresets]) -> list[PrusaPresets]:
    """The presets with each name naming one set of settings: where parts' presets of one
    kind share a name but differ, the first part's settings keep the name and each other set
    takes the name of the first part holding it after a dash (parts with equal settings
    share their preset)."""
    out = list(presets)
    for kind in PRESET_KINDS:
        first: dict[tuple[str, tuple], str] = {}  # (name, settings) -> first part holding them
        variants: dict[str, list[tuple]] = {}
        for p in presets:
            key = tuple(sorted(p.settings[kind].items()))
            first.setdefault((p.names[kind], key), p.part)
            if key not in variants.setdefault(p.names[kind], []):
                variants[p.names[kind]].append(key)
        renamed = []
        for p in out:
            name, key = p.names[kind], tuple(sorted(p.settings[kind].items()))
            if variants[name].index(key):
                name = f"{name} - {first[(name, key)]}"
            renamed.append(dataclasses.replace(p, names={**p.names, kind: name}))
        out = renamed
    return out


def design_presets(design: Design, printer: Printer) -> dict[str, PrusaPresets]:
    """Every part's presets ("net", "cable-<name>"), named uniquely across the design."""
    parts = [("net", design.net)] + [("cable", c) for c in design.cables]
    presets = [prusa_presets(kind, part, printer, load_print_style(part.print_style),
                             load_material(part.material)) for kind, part in parts]
    return {p.part: p for p in unique_preset_names(presets)}


def _lines(settings: dict[str, str]) -> list[str]:
    return [f"{k} = {v.replace(chr(10), chr(92) + 'n')}" for k, v in sorted(settings.items())]


def presets_ini_text(presets: PrusaPresets, kinds: tuple[str, ...] = PRESET_KINDS) -> str:
    """A flat .ini of the presets of `kinds` (all three: the whole config), with their names.

    Print and filament alone are loaded after a printer config: `prusa-slicer --load
    printer.ini --load this.ini`; a printer key in them would replace the lab's own."""
    s = {k: v for kind in kinds for k, v in presets.settings[kind].items()}
    s |= presets.ids(kinds)
    head = list(presets.header)
    if kinds != PRESET_KINDS:
        head.append(f"# the {' and '.join(kinds)} presets only: load it after your printer's "
                    "config (prusa-slicer --load printer.ini --load this.ini)")
    return "\n".join(head + _lines(s)) + "\n"


def prusa_bundle_text(presets: list[PrusaPresets]) -> str:
    """A PrusaSlicer config bundle: one `[print:NAME]`, `[filament:NAME]` and
    `[printer:NAME]` section per distinct preset (names made unique first), and `[presets]`
    selecting the first part's print and filament presets. Import it in the GUI with File >
    Import > Import Config Bundle; each print preset is offered with printers whose nozzle its
    condition admits."""
    presets = unique_preset_names(presets)
    seen: set[tuple[str, str]] = set()
    out = ["# printgen: PrusaSlicer 2.5 config bundle: print and filament presets for the "
           "parts, and a printer preset for printgen's printer",
           "# GUI: File > Import > Import Config Bundle; then pick your own printer (or this "
           "one) and these print and filament presets"]
    for kind in PRESET_KINDS:
        for p in presets:
            if (kind, p.names[kind]) in seen:
                continue
            seen.add((kind, p.names[kind]))
            s = dict(p.settings[kind])
            if kind == "print":
                s["compatible_printers_condition"] = p.compatible
            out += ["", f"[{kind}:{p.names[kind]}]", *_lines(s)]
    # [presets] selects on import: the print and filament only, so that the lab's own
    # printer stays the active one (PrusaSlicer's bundle loader activates every one named)
    out += ["", "[presets]", *(f"{kind} = {presets[0].names[kind]}"
                               for kind in ("print", "filament"))]
    return "\n".join(out) + "\n"


def prusa_ini_text(part_kind: str, design_part: NetDesign | CableDesign, printer: Printer,
                   style: PrintStyle, material: Material) -> str:
    """The whole .ini text (flat `key = value`, newlines in values as `\\n`): the three
    presets' settings and names."""
    return presets_ini_text(prusa_presets(part_kind, design_part, printer, style, material))


def write_prusa_ini(path: str | Path, part_kind: str, design_part: NetDesign | CableDesign,
                    printer: Printer, style: PrintStyle, material: Material) -> Path:
    """Write the .ini atomically; a bad design raises before the file is touched."""
    return write_text(path, prusa_ini_text(part_kind, design_part, printer, style, material))
