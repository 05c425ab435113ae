"""Read G-code (printgen's own or a slicer's) back into a `Toolpath` and summarise it.

Simulates G90/G91, M82/M83 (G91 makes E relative too, as Marlin 2), G92, G20/G21 and
G0/G1/G2/G3. A move extrudes when E grows and XY moves; its section is dE x filament area /
XY length and its bead width is that section / layer height (rectangle model). Retractions and
primes (E on a move without XY) are not deposits, nor are moves under a `;TYPE:` of a skirt,
brim, prime or purge line (their volume is `prime_volume_mm3`).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from printgen.errors import InputError
from printgen.parts.gcode.toolpath import TRAVEL, Toolpath

EXTRUDING = 1  # kind of a read-back extrusion move
Z_ROUND_MM = 1e-4  # extrusion Z values closer than this are one layer
NOT_PART = re.compile(r"skirt|brim|custom|prime|purge|wipe", re.IGNORECASE)  # as check_gcode
_WORD = re.compile(r"([A-Za-z])\s*([-+]?(?:\d+\.?\d*|\.\d+))")


@dataclass(frozen=True)
class Readback:
    """What a G-code file deposits.

    toolpath : moves read back (kind EXTRUDING or TRAVEL; width = section / layer height)
    volume_per_layer_mm3 : (k,) per extrusion layer, bottom first; layer_z_mm : (k,)
    paths_per_layer : (k,) runs of consecutive extrusion moves
    bounds_mm : (2, 3) min / max of extrusion end points
    """

    toolpath: Toolpath
    volume_per_layer_mm3: np.ndarray
    paths_per_layer: np.ndarray
    bounds_mm: np.ndarray
    filament_mm: float
    max_flow_mm3_per_s: float
    prime_volume_mm3: float = 0.0

    @property
    def volume_mm3(self) -> float:
        return float(self.volume_per_layer_mm3.sum())

    @property
    def layer_z_mm(self) -> np.ndarray:
        return self.toolpath.layer_z_mm

    @property
    def path_count(self) -> int:
        return int(self.paths_per_layer.sum())

    def summary(self) -> dict[str, object]:
        return {"layers": len(self.layer_z_mm), "volume_mm3": round(self.volume_mm3, 3),
                "volume_per_layer_mm3": [round(float(v), 3) for v in self.volume_per_layer_mm3],
                "layer_z_mm": [float(z) for z in self.layer_z_mm],
                "paths": self.path_count, "paths_per_layer": self.paths_per_layer.tolist(),
                "bounds_mm": self.bounds_mm.round(3).tolist(),
                "filament_mm": round(self.filament_mm, 3),
                "max_flow_mm3_per_s": round(self.max_flow_mm3_per_s, 3)}


def read_gcode(path: str | Path, *, filament_diameter_mm: float = 1.75) -> Readback:
    """Read a G-code file (see `read_gcode_text`)."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"G-code file not found: {p}")
    return read_gcode_text(p.read_text(encoding="utf-8", errors="replace"),
                           filament_diameter_mm=filament_diameter_mm)


def read_gcode_text(text: str, *, filament_diameter_mm: float = 1.75) -> Readback:
    """Parse G-code text into moves; raises InputError when nothing is extruded."""
    fil = math.pi * filament_diameter_mm ** 2 / 4
    rows = _simulate(text)
    all_rows = np.array(rows, dtype=float).reshape(-1, 9)
    part = all_rows[:, 8] == 0
    prime = float(np.sum(all_rows[~part, 3] * all_rows[~part, 6]) * fil)
    a = all_rows[part, :8]  # x, y, z, de, lxy, feed mm/min, extruding, new_path
    if not np.any(a[:, 6] > 0):
        raise InputError("the G-code extrudes nothing (no move with growing E and XY motion)")
    ext = a[:, 6] > 0
    zkey = np.round(a[:, 2] / Z_ROUND_MM) * Z_ROUND_MM
    layer_z = np.unique(zkey[ext])
    layer = np.clip(np.searchsorted(layer_z, zkey), 0, len(layer_z) - 1)
    heights = np.diff(np.concatenate([[0.0], layer_z]))
    vol = np.where(ext, a[:, 3] * fil, 0.0)
    area = np.where(ext, vol / np.maximum(a[:, 4], 1e-12), 0.0)
    h = np.where(ext, heights[layer], 0.0)
    speed = a[:, 5] / 60.0
    tp = Toolpath(a[:, 0:3].copy(), np.where(ext, area / np.maximum(h, 1e-12), 0.0), h,
                  speed, ext.astype(float), layer, np.where(ext, EXTRUDING, TRAVEL),
                  layer_z, "read back")
    starts = ext & (a[:, 7] > 0)
    pts = a[ext, 0:3]
    return Readback(
        toolpath=tp,
        volume_per_layer_mm3=np.bincount(layer[ext], weights=vol[ext], minlength=len(layer_z)),
        paths_per_layer=np.bincount(layer[starts], minlength=len(layer_z)),
        bounds_mm=np.vstack([pts.min(axis=0), pts.max(axis=0)]),
        filament_mm=float(a[ext, 3].sum()),
        max_flow_mm3_per_s=float(np.max(area * speed)),
        prime_volume_mm3=prime,
    )


def _simulate(text: str) -> list[tuple[float, ...]]:
    """Rows (x, y, z, dE, L_xy, feed, extruding, starts_path, not_part) for every XY move."""
    x = y = z = 0.0
    e = 0.0
    feed = 0.0
    abs_xyz, rel_e, unit = True, False, 1.0
    in_path = False
    last_z = None
    rows: list[tuple[float, ...]] = []
    not_part = 0.0
    for raw in text.splitlines():
        if raw.startswith(";TYPE:"):
            not_part = 1.0 if NOT_PART.search(raw[6:]) else 0.0
        code = raw.split(";", 1)[0].strip()
        if not code:
            continue
        words = _WORD.findall(code.split("*", 1)[0])
        if not words:
            continue
        if words[0][0].upper() == "N":
            words = words[1:]
            if not words:
                continue
        cmd = words[0][0].upper() + str(int(float(words[0][1]))) if words[0][1] else ""
        p = {k.upper(): float(v) for k, v in words[1:]}
        if cmd in ("G0", "G1", "G2", "G3"):
            if "F" in p:
                feed = p["F"] * unit
            nx = _axis(p, "X", x, abs_xyz, unit)
            ny = _axis(p, "Y", y, abs_xyz, unit)
            nz = _axis(p, "Z", z, abs_xyz, unit)
            de = 0.0
            if "E" in p:
                v = p["E"] * unit
                de = v if (rel_e or not abs_xyz) else v - e
                e = e + v if (rel_e or not abs_xyz) else v
            lxy = _arc_length(cmd, x, y, nx, ny, p, unit) if cmd in ("G2", "G3") \
                else math.hypot(nx - x, ny - y)
            extruding = de > 1e-9 and lxy > 1e-9
            if lxy > 1e-9 or nz != z:
                new_path = extruding and (not in_path or nz != last_z)
                rows.append((nx, ny, nz, de if extruding else 0.0, lxy, feed,
                             1.0 if extruding else 0.0, 1.0 if new_path else 0.0, not_part))
                in_path = extruding
                if extruding:
                    last_z = nz
            elif abs(de) > 1e-9:
                in_path = False  # retraction or prime ends a path
            x, y, z = nx, ny, nz
        elif cmd == "G90":
            abs_xyz = True
        elif cmd == "G91":
            abs_xyz = False
        elif cmd == "M82":
            rel_e = False
        elif cmd == "M83":
            rel_e = True
        elif cmd == "G20":
            unit = 25.4
        elif cmd == "G21":
            unit = 1.0
        elif cmd == "G92":
            x, y, z = (p.get(k, v / unit) * unit for k, v in (("X", x), ("Y", y), ("Z", z)))
            if "E" in p or not p:
                e = p.get("E", 0.0) * unit
        elif cmd in ("G10", "G11"):
            in_path = False
    return rows


def _axis(p: dict[str, float], k: str, old: float, absolute: bool, unit: float) -> float:
    if k not in p:
        return old
    return p[k] * unit if absolute else old + p[k] * unit


def _arc_length(cmd: str, x: float, y: float, nx: float, ny: float, p: dict[str, float],
                unit: float) -> float:
    i, j = p.get("I", 0.0) * unit, p.get("J", 0.0) * unit
    r = math.hypot(i, j)
    if r <= 0:
        return math.hypot(nx - x, ny - y)
    cx, cy = x + i, y + j
    a0, a1 = math.atan2(y - cy, x - cx), math.atan2(ny - cy, nx - cx)
    sweep = (a0 - a1) % (2 * math.pi) if cmd == "G2" else (a1 - a0) % (2 * math.pi)
    return r * (sweep or 2 * math.pi)
