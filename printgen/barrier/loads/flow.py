"""The flow itself: hydrostatic loading plus drag on every submerged strand, 0.5 rho v^2 l d
(drag coefficient 1), with the velocity rising with the water depth at the prototype's
Froude number: v(h) = v_f sqrt(h / h_f), v_f the prototype file's velocity at its flow depth
h_f ([flow] depth_m, default the barrier's height), on the model v_f / sqrt(lambda) at
h_f / lambda (Froude similitude), so that both barriers see the same Froude number at the
same relative loading (barrier-physics.md, sections 2 and 3; Lambert et al. 2023,
doi:10.1061/JHEND8.HYENG-13070: hydrodynamic loading = hydrostatic + drag). At h = h_f the
load is the paper's hydrodynamic one (the simple barrier: 6 m/s at h = h_B, section 8)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from printgen.barrier.loads import LoadCase, LoadsAt, SceneView, Site, hydrostatic
from printgen.barrier.loads.drag import strand_drag
from printgen.units import G


def velocity(s: SceneView, site: Site, r: float) -> float:
    """The approach velocity (m/s) at relative loading r: constant Froude number."""
    depth = site.depth or s.height
    return float(site.velocity) * math.sqrt(max(r, 0.0) * s.height / depth)


def loads(s: SceneView, site: Site) -> LoadsAt:
    """Hydrostatic loads and drag at the level's velocity on the submerged free nodes."""
    still = hydrostatic.loads(s, site)
    drag_at = strand_drag(s, site.strand_diameter)

    def loads_at(r: float) -> list:
        return [*still(r), drag_at(r, velocity(s, site, r))]

    return loads_at


def per_level(s: SceneView, site: Site, levels: np.ndarray
              ) -> tuple[dict[str, Any], str]:
    """The velocity and Froude number at each level."""
    v = np.array([velocity(s, site, float(r)) for r in levels])
    depth = np.asarray(levels, dtype=float) * s.height
    froude = np.divide(v, np.sqrt(G * depth), out=np.zeros_like(v), where=depth > 0)
    top = float(np.max(levels))
    text = (f"v = {site.velocity:.4g} m/s x sqrt(h / {site.depth or s.height:.4g} m): "
            f"{velocity(s, site, 0.5):.4g} m/s at h/h_B = 0.5, {velocity(s, site, 1.0):.4g} at "
            f"1, {velocity(s, site, top):.4g} at {top:g}")
    return {"velocity_m_per_s": v, "froude": froude}, text


CASE = LoadCase(
    "flow", "hydrostatic + drag, velocity rising with the depth (Froude number held)", loads,
    (hydrostatic.ASSUMPTION,
     ("loading: flow", ("hydrostatic plus 0.5 rho v^2 l d on each submerged free node (drag "
      "coefficient 1, l its share of strand length, d the strand diameter), ramped in over "
      "one node row; v(h) = v_f sqrt(h / h_f): the prototype's Froude number v_f / sqrt(g "
      "h_f) held as the water rises; model v_f / sqrt(lambda) at h_f / lambda (Froude)"),
     ("Lambert et al. 2023: hydrodynamic nodal loads, drag coefficient 1 (barrier-physics.md "
      "sections 2, 3); the depth rule is printgen's (printgen docs: Load cases)"))),
    per_level=per_level)
