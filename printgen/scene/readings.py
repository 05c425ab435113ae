"""What a lab reads in the flume, in its own units, and back: the string-potentiometer change
of each sensor wire (mm), the mid-height deflection and the top-centre lowering (mm), the
water depth (mm) for each relative loading, and the tensions (N).

The pre-print check works in normalised quantities (strain of a sensor row, deflection /
width, lowering / height, h / h_B); a reading in mm is the normalised value times the printed
model's own length: the sensor row's rest length (the wire from its anchor over the row's
nodes, printgen.verification.compare.wire_elongation), the net's width or height, the barrier height
h_B (the net's height: the water depth at h / h_B = 1).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from printgen.scaling.record import Design
from printgen.scene.options import build_scene
from printgen.scene.scenes import BarrierScene, sensor_wires
from printgen.scene.solvernet import path_length
from printgen.units import MM

SENSORS = {"strain_bottom": "bottom", "strain_top": "top", "strain_mid": "mid"}
# raw CSV column (mm) -> METRICS key; the water depth column stands for h_over_hb
RAW_COLUMNS = {"bottom_sensor_mm": "strain_bottom", "top_sensor_mm": "strain_top",
               "mid_sensor_mm": "strain_mid", "deflection_mm": "deflection",
               "top_lowering_mm": "lowering"}
DEPTH_COLUMN = "water_depth_mm"


@dataclass(frozen=True)
class FlumeUnits:
    """The printed model's lengths that turn normalised quantities into mm (all in mm)."""

    width_mm: float
    height_mm: float
    row_mm: dict[str, float]  # sensor row -> rest length of the wire along the row

    def length_mm(self, metric: str) -> float:
        """mm per unit of METRICS quantity `metric` (a strain of 1, a deflection of 1 width)."""
        if metric in SENSORS:
            return self.row_mm[SENSORS[metric]]
        return {"deflection": self.width_mm, "lowering": self.height_mm}[metric]

    def to_record(self) -> dict[str, object]:
        return {"width_mm": self.width_mm, "height_mm": self.height_mm,
                "sensor_row_mm": dict(self.row_mm)}


def flume_units(scene: BarrierScene) -> FlumeUnits:
    """The lengths of `scene` (the printed model's solver scene) in mm."""
    x0 = scene.nodes
    rows = {}
    for row in SENSORS.values():  # a sensor read from two rows: their weighted rest lengths
        rows[row] = sum(w.weight * (path_length(x0, w.nodes, w.exit)
                                    - float(np.linalg.norm(w.exit - x0[w.nodes[-1]])))
                        for w in sensor_wires(scene.wires, row)) / MM
    return FlumeUnits(scene.width / MM, scene.height / MM, rows)


def design_units(design: Design) -> FlumeUnits:
    """`flume_units` of the printed model of `design`."""
    return flume_units(build_scene(design))
