"""The sensors are part of the test design: the three string potentiometers pull on the printed
model (each wire `[flume] sensor_force_n`, about 1 N in Lambert et al. 2023,
doi:10.1061/JHEND8.HYENG-13070), and a small model's whole water load can be of that order.

Their share of the load at a relative loading h / h_B is the three wires' pull over the
hydrostatic resultant on the model's net, rho g sum(max(h - z_i, 0)) A* over its nodes
(reference, section 3: the nodal hydrostatic loads). Where the share at SENSOR_LEVEL exceeds
SENSOR_SHARE, a FAIL may be the sensors' and not the net's: the model is compared again with a
prototype whose wires pull the same share of its load (the model's force x lambda^3, forces
scale as lambda^-3). When that comparison passes, the net is similar and the sensors are too
strong at this scale; the largest force that keeps the share at SENSOR_SHARE is given.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from printgen.scene.scenes import BarrierScene, sensor_of
from printgen.units import RHO_WATER, G
from printgen.verification.compare import Mismatch

SENSOR_SHARE = 0.10  # the sensors' pull over the water load above which they disturb the test
SENSOR_LEVEL = 1.0  # the level that matters: water at the barrier's top (the design loading)


def sensor_count(scene: BarrierScene) -> int:
    """The scene's sensors (a mid-height sensor read from two rows is one sensor)."""
    return len({sensor_of(k) for k in scene.wires})


def scene_sensor_force(scene: BarrierScene) -> float:
    """The pull (N) of each of the scene's sensors (0: they only read)."""
    return sum(w.force for w in scene.wires.values()) / max(sensor_count(scene), 1)


def water_resultant(scene: BarrierScene, level: float) -> float:
    """Hydrostatic resultant (N) on the scene's net at relative loading `level` (h / h_B), from
    its rest node heights and tributary area A* (reference, section 3)."""
    head = level * scene.height - scene.nodes[:, 2]
    return float(RHO_WATER * G * np.clip(head, 0.0, None).sum() * scene.area_per_node)


@dataclass(frozen=True)
class SensorCheck:
    """The sensors' share of the model's water load, and (when it exceeds `threshold` at
    `level`) the model against a prototype whose wires pull force x lambda^3.

    force_n : N per wire on the model; count : sensors; levels, shares : (k,) h / h_B and the
    pull / water load there (NaN where the load is zero); load_n : (k,) water load N;
    share, load_at_level_n : the share and the water load (N) at `level`; limit_n : the force
    per wire whose share at `level` is `threshold`; loaded : the mismatches against the loaded
    prototype (None: not needed, the share is small)."""

    force_n: float
    count: int
    levels: np.ndarray
    shares: np.ndarray
    load_n: np.ndarray
    threshold: float
    level: float
    share: float
    load_at_level_n: float
    limit_n: float
    loaded: list[Mismatch] | None = None

    @property
    def too_strong(self) -> bool:
        return self.share > self.threshold

    @property
    def net_similar(self) -> bool:
        """True when the model matches the prototype under equally scaled sensor forces."""
        return self.loaded is not None and all(m.ok for m in self.loaded)

    def text(self) -> str:
        """One sentence: the share, and what to do when it is too large."""
        said = (f"the {self.count} sensor wires pull {self.count} x {self.force_n:.3g} N = "
                f"{self.share:.0%} of the model's water load at h/h_B = {self.level:g} "
                f"({self.load_at_level_n:.3g} N)")
        if not self.too_strong:
            return f"{said}, within {self.threshold:.0%}"
        use = f"use <= {self.limit_n:.2g} N (flume.sensor_force_n in the prototype file)"
        if self.net_similar:
            return (f"sensors too strong at this scale: {said}, over {self.threshold:.0%}; "
                    "with the prototype's wires pulling as much of its load (x lambda^3) the "
                    f"model matches it: the net is similar; {use}")
        return (f"{said}, over {self.threshold:.0%}: sensors too strong at this scale, {use}; "
                "the model fails even against a prototype with equally scaled sensors")

    def to_record(self) -> dict[str, Any]:
        return {"force_n": self.force_n, "sensors": self.count, "levels": self.levels,
                "share_of_water_load": self.shares, "water_load_n": self.load_n,
                "threshold": self.threshold, "level": self.level, "share": self.share,
                "too_strong": self.too_strong, "limit_n": self.limit_n,
                "loaded_prototype_mismatches": self.loaded,
                "net_similar_with_scaled_sensors": (self.net_similar if self.loaded is not None
                                                    else None),
                "text": self.text(),
                "definition": ("share = sensors x force / hydrostatic resultant rho g "
                               "sum(max(h - z, 0)) A* on the model's net")}


def sensor_check(scene: BarrierScene, force: float, levels: np.ndarray,
                 loaded: list[Mismatch] | None = None) -> SensorCheck:
    """The sensors' share on the model `scene` (wires pulling `force` N each) at `levels`."""
    lv = np.asarray(levels, float)
    load = np.array([water_resultant(scene, r) for r in lv])
    count = sensor_count(scene)
    with np.errstate(divide="ignore", invalid="ignore"):
        shares = np.where(load > 0, count * force / load, np.nan)
    at = water_resultant(scene, SENSOR_LEVEL)
    return SensorCheck(force, count, lv, shares, load, SENSOR_SHARE, SENSOR_LEVEL,
                       count * force / at, at, SENSOR_SHARE * at / count, loaded)


def needs_loaded_prototype(scene: BarrierScene, force: float) -> bool:
    """True when the sensors' share at SENSOR_LEVEL exceeds SENSOR_SHARE."""
    return sensor_count(scene) * force > SENSOR_SHARE * water_resultant(scene, SENSOR_LEVEL)
