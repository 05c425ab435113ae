"""Printer profiles (bed, nozzle, filament, G-code flavour, start/end code) and print styles
(bead width and layer heights of one pass, and the slicer's width rules) in millimetres."""

from __future__ import annotations

from dataclasses import dataclass

from printgen.errors import PrintabilityError
from printgen.inputs.profiles import load_raw
from printgen.inputs.schema import Field, positive, read_table

MAX_LAYER_FRACTION = 0.75  # a layer above 0.75 x nozzle does not bond reliably
# Holes of 2-6 mm printed with 0.4-0.5 mm nozzles come out 0.1-0.3 mm small in diameter
# (a measured 3.2 mm eyelet came out at 3.15-3.18 mm, before shrinkage of the
# perimeter); 0.2 mm is the default, measure a test eyelet and set your printer's value.
HOLE_COMPENSATION_MM = 0.2

PRINTER = [
    Field("name", str),
    Field("description", str, required=False, default="", multiline=True),
    positive("nozzle_diameter_mm", 3.0, si=False),
    positive("filament_diameter_mm", 3.5, si=False),
    positive("bed_x_mm", 2000.0, si=False),
    positive("bed_y_mm", 2000.0, si=False),
    positive("max_height_mm", 2000.0, si=False),
    Field("bed_margin_mm", float, lo=0.0, hi=50.0, si=False, required=False, default=5.0),
    Field("min_bead_factor", float, lo=0.3, hi=1.5, si=False, required=False, default=0.85,
          help="narrowest bead as a fraction of the nozzle diameter"),
    Field("max_bead_factor", float, lo=1.0, hi=4.0, si=False, required=False, default=2.0,
          help="widest bead as a multiple of the nozzle diameter"),
    positive("travel_speed_mm_per_s", 1000.0, si=False, required=False, default=150.0),
    Field("hole_compensation_mm", float, lo=0.0, hi=0.8, si=False, required=False,
          default=HOLE_COMPENSATION_MM,
          help="added to every hole diameter (eyelets, net loops): FDM holes print small"),
    Field("gcode_flavor", str, choices=("marlin2", "marlin", "reprap", "klipper"), si=False),
    Field("start_gcode", str, required=False, default="", multiline=True),
    Field("end_gcode", str, required=False, default="", multiline=True),
    Field("net_print", str, required=False, default="",
          help="the net print style made for this nozzle (a prototype's [model] net_print "
               "overrides it; empty: the bundled default)"),
    Field("cable_print", str, required=False, default="",
          help="the cable print style made for this nozzle (as net_print)"),
]
PRINT_STYLE = [
    Field("name", str),
    Field("description", str, required=False, default="", multiline=True),
    Field("component", str, choices=("net", "cable")),
    positive("bead_width_mm", 5.0, si=False),
    positive("first_layer_height_mm", 2.0, si=False),
    positive("layer_height_mm", 2.0, si=False),
    Field("slicer_width_factor", float, lo=1.0, hi=1.5, si=False, required=False, default=1.15,
          help="slicer extrusion width / strand width (slicers.md: 1.15 makes one bead)"),
    Field("slicer_min_bead_factor", float, lo=0.5, hi=1.0, si=False, required=False,
          default=0.85, help="slicer min_bead_width / strand width"),
    Field("crossing_flow_factor", float, lo=0.0, hi=1.0, si=False, required=False, default=1.0,
          help="direct G-code: flow over a strand crossing, as a fraction of full flow"),
]


@dataclass(frozen=True)
class Printer:
    """A printer: nozzle, filament, bed (mm), flavour, start/end G-code."""

    key: str
    name: str
    description: str
    nozzle_diameter_mm: float
    filament_diameter_mm: float
    bed_x_mm: float
    bed_y_mm: float
    max_height_mm: float
    bed_margin_mm: float
    min_bead_factor: float
    max_bead_factor: float
    travel_speed_mm_per_s: float
    hole_compensation_mm: float
    gcode_flavor: str
    start_gcode: str
    end_gcode: str
    net_print: str = ""  # the print styles made for its nozzle (empty: the bundled defaults)
    cable_print: str = ""

    @property
    def min_bead_mm(self) -> float:
        return self.min_bead_factor * self.nozzle_diameter_mm

    @property
    def max_bead_mm(self) -> float:
        return self.max_bead_factor * self.nozzle_diameter_mm

    @property
    def max_layer_mm(self) -> float:
        return MAX_LAYER_FRACTION * self.nozzle_diameter_mm


@dataclass(frozen=True)
class PrintStyle:
    """How one pass is laid: bead width and layer heights (mm), slicer width rules."""

    key: str
    name: str
    description: str
    component: str
    bead_width_mm: float
    first_layer_height_mm: float
    layer_height_mm: float
    slicer_width_factor: float
    slicer_min_bead_factor: float
    crossing_flow_factor: float

    def layer_heights_mm(self, n_layers: int) -> list[float]:
        """Heights of `n_layers` stacked layers, first layer first."""
        return [self.first_layer_height_mm] + [self.layer_height_mm] * (n_layers - 1)


def load_printer(name: str) -> Printer:
    data, files = load_raw("printers", name)
    return Printer(key=files[0].stem, **read_table(data, PRINTER, where=str(files[0])))


def load_print_style(name: str) -> PrintStyle:
    data, files = load_raw("prints", name)
    return PrintStyle(key=files[0].stem, **read_table(data, PRINT_STYLE, where=str(files[0])))


def check_pass(printer: Printer, bead_width_mm: float, layer_height_mm: float,
               *, where: str) -> None:
    """Raise PrintabilityError when one bead cannot be printed with this printer's nozzle."""
    noz = printer.nozzle_diameter_mm
    if bead_width_mm < printer.min_bead_mm - 1e-12:
        raise PrintabilityError(
            f"{where}: bead width {bead_width_mm:.3g} mm is below {printer.min_bead_mm:.3g} mm "
            f"({printer.min_bead_factor:g} x the {noz:g} mm nozzle of {printer.key}); "
            "use more, wider passes or a smaller nozzle")
    if bead_width_mm > printer.max_bead_mm + 1e-12:
        raise PrintabilityError(
            f"{where}: bead width {bead_width_mm:.3g} mm exceeds {printer.max_bead_mm:.3g} mm "
            f"({printer.max_bead_factor:g} x nozzle {noz:g} mm); split it into more passes")
    if layer_height_mm > printer.max_layer_mm + 1e-12:
        raise PrintabilityError(
            f"{where}: layer height {layer_height_mm:.3g} mm exceeds {printer.max_layer_mm:.3g} mm "
            f"({MAX_LAYER_FRACTION} x nozzle {noz:g} mm); lower layer_height_mm in the print "
            "style or use a larger nozzle")


def nozzle_range_mm(printer: Printer, bead_width_mm: float,
                    layer_heights_mm: tuple[float, ...] | list[float]) -> tuple[float, float]:
    """(smallest, largest) nozzle diameter in mm that `check_pass` accepts for these beads and
    layers with this printer's bead factors: a layer at most MAX_LAYER_FRACTION x the nozzle,
    a bead between min_bead_factor and max_bead_factor x it."""
    lo = max(max(layer_heights_mm) / MAX_LAYER_FRACTION, bead_width_mm / printer.max_bead_factor)
    return lo, bead_width_mm / printer.min_bead_factor
