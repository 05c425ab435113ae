"""Print time, filament length and mass of a part from its direct toolpath, as slicers put
them in their G-code headers.

Time: every move (travel and extrusion) at its programmed speed, no acceleration limits,
plus each retraction and its unretraction at the material's retract speed; heating, homing and
the prime line are not counted (state it where shown). Filament: extruded volume over the
filament's section; mass: volume x the material profile's density.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from printgen.inputs.materials import Material
from printgen.inputs.printers import Printer
from printgen.parts.gcode.toolpath import COMB, TRAVEL, Toolpath

RETRACT_MIN_TRAVEL_MM = 2.0  # travels shorter than this are not retracted (no ooze gap)
NOT_COUNTED = "moves at their set speed without acceleration, retractions included; heating, " \
              "homing and the prime line not counted"


@dataclass(frozen=True)
class PrintEstimate:
    """One part's print: time in s, filament in mm, mass in g, extruded volume in mm^3."""

    seconds: float
    filament_mm: float
    mass_g: float
    volume_mm3: float

    def to_record(self) -> dict[str, float]:
        return {"print_time_s": self.seconds, "filament_mm": self.filament_mm,
                "mass_g": self.mass_g, "volume_mm3": self.volume_mm3}

    def header_lines(self) -> list[str]:
        """G-code header comments, in the form PrusaSlicer writes them."""
        return [f"; estimated printing time (normal mode) = {duration(self.seconds)}",
                f"; filament used [mm] = {self.filament_mm:.2f}",
                f"; filament used [cm3] = {self.volume_mm3 / 1e3:.3f}",
                f"; filament used [g] = {self.mass_g:.3f}",
                f"; printgen estimate: {NOT_COUNTED}"]


def print_estimate(tp: Toolpath, printer: Printer, material: Material) -> PrintEstimate:
    """Time, filament and mass of printing `tp` on `printer` with `material`."""
    lengths = tp.lengths_mm()
    dz = np.concatenate([[0.0], np.abs(np.diff(tp.xyz_mm[:, 2]))])
    speed = np.maximum(tp.speed_mm_per_s, 1e-9)
    seconds = float(np.sum(np.hypot(lengths, dz)[1:] / speed[1:]))
    travel = (tp.kind == TRAVEL) | ~tp.extruding
    retracted = travel & (tp.kind != COMB) & (lengths >= RETRACT_MIN_TRAVEL_MM)
    p = material.print
    if p.retract_length_mm > 0 and p.retract_speed_mm_per_s > 0:
        seconds += float(np.count_nonzero(retracted)) * 2 * p.retract_length_mm \
            / p.retract_speed_mm_per_s
    volume = tp.volume_mm3
    filament = volume / (math.pi * printer.filament_diameter_mm ** 2 / 4)
    return PrintEstimate(seconds, filament, volume * 1e-3 * material.density / 1e3, volume)


def duration(seconds: float) -> str:
    """'1h 02m 03s' / '12m 03s' / '45s', as slicers write it."""
    s = round(seconds)
    h, m, s = s // 3600, s // 60 % 60, s % 60
    return f"{h}h {m:02d}m {s:02d}s" if h else (f"{m}m {s:02d}s" if m else f"{s}s")
