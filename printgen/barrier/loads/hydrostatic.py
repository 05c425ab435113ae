"""Hydrostatic loading: water raised behind a folded film from h / h_B = 0 to the overflow,
rho g (r h_B - z) A* on every free node at its current height (barrier-physics.md, sections
3 and 4; Lambert et al. 2023, doi:10.1061/JHEND8.HYENG-13070)."""

from __future__ import annotations

import numpy as np

from printgen import solver
from printgen.barrier.loads import FLOW, LoadCase, LoadsAt, SceneView, Site
from printgen.units import RHO_WATER, G


def loads(s: SceneView, site: Site) -> LoadsAt:
    """Hydrostatic rho g (r h_B - z) A* on the scene's free nodes at their current height."""
    free = np.flatnonzero(~s.fixed)

    def loads_at(r: float) -> list:
        return [solver.Hydrostatic(free, s.area_per_node, r * s.height, tuple(FLOW),
                                   rho=RHO_WATER, g=G)]

    return loads_at


ASSUMPTION = ("loading", ("hydrostatic rho g (h - z) A* at the current node height, h/h_B = 0 "
              "to 1.1; the folded film adds no stiffness"),
              ("Lambert et al. 2023: nodal hydrostatic loads, loading test behind a folded "
               "film (Fig. 6a)"))
CASE = LoadCase("hydrostatic", "hydrostatic (z at the current node height)", loads,
                (ASSUMPTION,))
