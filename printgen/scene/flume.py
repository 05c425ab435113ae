"""The printed model as mounted for its loading test, in mm: the net's outline and strands,
its border cables, the anchor pins (the corner nodes, where the net's and both cables'
eyelets go on one pin), the edges held along their length (the flume's side sheets; the bed
and the banks of a net without border cables), and each sensor wire: where it is anchored,
the row it runs over and where its string potentiometer stands.

Everything is read from the model's solver scene (`printgen.scene.scenes`, whose
docstring states the routing), so the drawing shows what the check solved. Coordinates:
x across the flume from the net's left edge, z up from the flume bed (the net's bottom edge).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from printgen.scene.readings import SENSORS
from printgen.scene.scenes import BarrierScene, sensor_wires
from printgen.units import MM

DIGITS = 4  # decimals of mm kept in the record (0.1 um)
SIDE_NAMES = {"left": "left side sheet", "right": "right side sheet", "bottom": "flume bed"}


@dataclass(frozen=True)
class Sensor:
    """One sensor wire (mm): anchored at `anchor_mm` (x, z), over its row's nodes (`route_mm`,
    (k, 2), anchor first), to the potentiometer at `potentiometer_mm`; `along_row_mm` is the
    row's rest length (the reading's divisor), `free_mm` the wire beyond the right edge."""

    metric: str
    row: str
    anchor_mm: tuple[float, float]
    potentiometer_mm: tuple[float, float]
    route_mm: np.ndarray
    along_row_mm: float
    free_mm: float
    force_n: float


@dataclass(frozen=True)
class FlumeLayout:
    """The mounted model in mm (see the module docstring)."""

    width_mm: float
    height_mm: float
    mounting: str
    pins_mm: np.ndarray  # (k, 2) anchor pins: empty without border cables
    held_mm: dict[str, np.ndarray]  # side -> (k, 2) nodes held along that edge
    cables_mm: dict[str, np.ndarray]  # cable -> (k, 2) its path, anchor to anchor
    strands_mm: np.ndarray  # (m, 2, 2) the net's strands at rest
    sensors: tuple[Sensor, ...]

    def to_record(self) -> dict[str, object]:
        def r(v):
            return np.round(np.asarray(v, dtype=float), DIGITS).tolist()

        return {"width_mm": round(self.width_mm, DIGITS),
                "height_mm": round(self.height_mm, DIGITS),
                "mounting": self.mounting, "anchor_pins_mm": r(self.pins_mm),
                "held_edges": {k: {"by": SIDE_NAMES[k], "nodes": len(v),
                                   "from_mm": r(v[0]), "to_mm": r(v[-1])}
                               for k, v in self.held_mm.items()},
                "cables": {k: {"from_mm": r(v[0]), "to_mm": r(v[-1])}
                           for k, v in self.cables_mm.items()},
                "sensors": [{"metric": s.metric, "row": s.row, "anchor_mm": r(s.anchor_mm),
                             "potentiometer_mm": r(s.potentiometer_mm),
                             "row_height_mm": r(s.anchor_mm[1]),
                             "along_row_mm": round(s.along_row_mm, DIGITS),
                             "beyond_edge_mm": round(s.free_mm, DIGITS),
                             "nodes_passed": len(s.route_mm), "force_n": s.force_n}
                            for s in self.sensors]}


def _xz(points: np.ndarray) -> np.ndarray:
    """(k, 2) mm in the net's plane (x across, z up) of (k, 3) m points."""
    return np.asarray(points)[..., [0, 2]] / MM


def flume_layout(scene: BarrierScene) -> FlumeLayout:
    """The layout of `scene` (the printed model's, as mounted) in mm."""
    x0 = scene.nodes
    xz = _xz(x0)
    lo, hi = xz.min(axis=0), xz.max(axis=0)
    tol = 1e-6 * float(max(hi - lo))
    corners = [scene.rows[k][i] for k in ("bottom", "top") for i in (0, -1)]
    pins = xz[corners] if scene.cables else np.zeros((0, 2))
    held_idx = np.flatnonzero(scene.fixed & ~np.isin(np.arange(len(xz)), corners)
                              if scene.cables else scene.fixed)
    sides = {"left": np.abs(xz[held_idx, 0] - lo[0]) < tol,
             "right": np.abs(xz[held_idx, 0] - hi[0]) < tol,
             "bottom": np.abs(xz[held_idx, 1] - lo[1]) < tol}
    held = {}
    for side, mask in sides.items():
        idx = held_idx[mask]
        if idx.size:
            key = xz[idx, 1] if side != "bottom" else xz[idx, 0]
            held[side] = xz[idx[np.argsort(key)]]
    cables = {k: xz[nodes] for k, (nodes, _) in scene.cables.items()}
    sensors = []
    for metric, row in SENSORS.items():
        wires = sensor_wires(scene.wires, row)
        w = max(wires, key=lambda v: v.weight)
        route, exit_xz = xz[w.nodes].copy(), _xz(w.exit)
        if len(wires) > 1:  # read between two rows: drawn at its own height (the module)
            z = sum(v.weight * float(np.median(xz[v.nodes, 1])) for v in wires)
            route[:, 1], exit_xz[1] = z, z
        along = sum(v.weight * float(np.sum(np.linalg.norm(np.diff(x0[v.nodes], axis=0),
                                                           axis=1))) for v in wires) / MM
        free = float(np.linalg.norm(w.exit - x0[w.nodes[-1]])) / MM
        sensors.append(Sensor(metric, row, tuple(route[0]), tuple(exit_xz), route, along,
                              free, sum(v.force for v in wires)))
    return FlumeLayout(float(hi[0] - lo[0]), float(hi[1] - lo[1]), scene.mounting, pins, held,
                       cables, xz[scene.elements], tuple(sensors))
