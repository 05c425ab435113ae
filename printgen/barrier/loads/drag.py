"""Hydrostatic loading plus drag at the flow's velocity, scaled by Froude on the model:
0.5 rho v^2 l d on each free node's share l of strand length, drag coefficient 1
(barrier-physics.md, section 3: F_dyn; Lambert et al. 2023, doi:10.1061/JHEND8.HYENG-13070).
A node's drag grows from zero as the water rises over one node row (`solver.Drag` ramp)."""

from __future__ import annotations

from typing import Any

import numpy as np

import solver
from printgen.barrier.loads import FLOW, LoadCase, LoadsAt, Site, hydrostatic
from printgen.units import RHO_WATER


def loads(s: Any, site: Site) -> LoadsAt:
    """The hydrostatic loads, and drag at `site.velocity` on the submerged free nodes."""
    still = hydrostatic.loads(s, site)
    free = np.flatnonzero(~s.fixed)
    d = s.nodes[s.elements[:, 1]] - s.nodes[s.elements[:, 0]]
    strand_per_node = float(np.linalg.norm(d, axis=1).sum()) / len(s.nodes)
    row_gap = float(np.diff(np.unique(np.round(s.nodes[:, 2], 12))).min())  # node rows apart

    def loads_at(r: float) -> list:
        return [*still(r), solver.Drag(free, strand_per_node, site.strand_diameter,
                                       site.velocity, r * s.height, tuple(FLOW),
                                       rho=RHO_WATER, ramp=row_gap)]

    return loads_at


CASE = LoadCase(
    "drag", "hydrostatic + drag at the Froude-scaled velocity", loads,
    (hydrostatic.ASSUMPTION,
     ("loading: drag", ("0.5 rho v^2 l d on each submerged free node (drag coefficient 1, l "
      "its share of strand length, d the strand diameter), ramped in over one node row; "
      "model velocity v / sqrt(lambda) (Froude)"),
     "Lambert et al. 2023: hydrodynamic nodal loads, drag coefficient 1")))
