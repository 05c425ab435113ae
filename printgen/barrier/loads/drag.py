"""Hydrostatic loading plus drag at the flow's velocity, the same at every load level
(scaled by Froude on the model): 0.5 rho v^2 l d on each free node's share l of strand
length, drag coefficient 1 (barrier-physics.md, sections 3 and 7: F_dyn, and the scene
simple-pinned's drag at 6 m/s whatever the depth; Lambert et al. 2023,
doi:10.1061/JHEND8.HYENG-13070). A node's drag grows from zero as the water rises over one
node row (`solver.Drag` ramp). `flow` is the same load with the velocity rising with the
depth (constant Froude number); this case keeps the reference scenes' fixed velocity."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from printgen import solver
from printgen.barrier.loads import FLOW, LoadCase, LoadsAt, SceneView, Site, hydrostatic
from printgen.units import RHO_WATER


def strand_per_node(s: SceneView) -> float:
    """l (m): the scene's strand length per node (the drag and the jam's net loss use it)."""
    d = s.nodes[s.elements[:, 1]] - s.nodes[s.elements[:, 0]]
    return float(np.linalg.norm(d, axis=1).sum()) / len(s.nodes)


def strand_drag(s: SceneView, diameter: float) -> Callable[[float, float], solver.Drag]:
    """(r, v) -> the drag 0.5 rho v^2 l d on the scene's free nodes wetted at level r h_B
    (l the strand length per node, d = `diameter`), ramped in over one node row."""
    free = np.flatnonzero(~s.fixed)
    per_node = strand_per_node(s)
    row_gap = float(np.diff(np.unique(np.round(s.nodes[:, 2], 12))).min())  # node rows apart

    def drag_at(r: float, v: float) -> solver.Drag:
        return solver.Drag(free, per_node, diameter, v, r * s.height, tuple(FLOW),
                           rho=RHO_WATER, ramp=row_gap)

    return drag_at


def loads(s: SceneView, site: Site) -> LoadsAt:
    """The hydrostatic loads, and drag at `site.velocity` on the submerged free nodes."""
    still = hydrostatic.loads(s, site)
    drag_at = strand_drag(s, site.strand_diameter)

    def loads_at(r: float) -> list:
        return [*still(r), drag_at(r, site.velocity)]

    return loads_at


def per_level(s: SceneView, site: Site, levels: np.ndarray
              ) -> tuple[dict[str, Any], str]:
    """The velocity at each level: the site's, whatever the depth."""
    v = np.full(len(levels), float(site.velocity))
    return {"velocity_m_per_s": v}, f"velocity {site.velocity:.4g} m/s at every level"


CASE = LoadCase(
    "drag", "hydrostatic + drag at the Froude-scaled velocity, fixed at every level", loads,
    (hydrostatic.ASSUMPTION,
     ("loading: drag", ("0.5 rho v^2 l d on each submerged free node (drag coefficient 1, l "
      "its share of strand length, d the strand diameter), ramped in over one node row; "
      "v the prototype file's velocity at every load level (not depth dependent; --load "
      "flow lets it rise with the depth); model velocity v / sqrt(lambda) (Froude)"),
     ("Lambert et al. 2023: hydrodynamic nodal loads, drag coefficient 1; barrier-physics.md "
      "section 7, scene simple-pinned (6 m/s at every level)"))),
    per_level=per_level)
