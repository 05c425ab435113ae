"""The simple-pinned scene in OpenSeesPy (the `bench` extra), for a side-by-side benchmark.

Corotational trusses (`corotTruss`) of a tension-only material (`Elastic E 0 0`: no
compression stiffness), nodal loads at the initial node height (OpenSees has no load that
follows the node height), Newton with line search under load control, `BandSPD` system. A flat
net without pretension has no out-of-plane stiffness at the start, so each strand gets a small
initial strain (`InitStrainMaterial`, PRESTRAIN) that is released after loading
(`epsInit` -> 0) with one more solve at full load.
"""

from __future__ import annotations

import time

import numpy as np

PRESTRAIN = 1e-6  # initial tension strain that lets OpenSees factorize the flat net's tangent
STEPS = 10  # load steps


def solve_opensees(nodes, fixed, elements, ea, loads, *, steps: int = STEPS, tol: float = 1e-6,
                   max_iter: int = 100):
    """Displacements (n, 3) m, seconds, converged, note."""
    import openseespy.opensees as ops

    t0 = time.perf_counter()
    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 3)
    for k, (x, y, z) in enumerate(nodes):
        ops.node(k + 1, float(x), float(y), float(z))
        if fixed[k]:
            ops.fix(k + 1, 1, 1, 1)
    ops.uniaxialMaterial("Elastic", 1, 1.0, 0.0, 0.0)  # E, damping, E in compression = 0
    ops.uniaxialMaterial("InitStrainMaterial", 2, 1, -PRESTRAIN)  # negative: tension here
    for k, (i, j) in enumerate(elements):
        ops.element("corotTruss", k + 1, int(i) + 1, int(j) + 1, float(ea), 2)
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    for k in np.flatnonzero(np.abs(loads).sum(axis=1) > 0):
        ops.load(int(k) + 1, *map(float, loads[k]))
    ops.system("BandSPD")
    ops.numberer("RCM")
    ops.constraints("Plain")
    ops.test("NormUnbalance", tol * float(np.abs(loads).max()), max_iter, 0)
    ops.algorithm("NewtonLineSearch")
    ops.integrator("LoadControl", 1.0 / steps)
    ops.analysis("Static")
    ok = ops.analyze(steps) == 0
    if ok:  # release the starting strain and solve again at full load
        ops.parameter(1)
        for k in range(len(elements)):
            ops.addToParameter(1, "element", k + 1, "epsInit")
        ops.updateParameter(1, 0.0)
        ops.integrator("LoadControl", 0.0)
        ok = ops.analyze(1) == 0
    disp = np.array([ops.nodeDisp(k + 1) for k in range(len(nodes))])
    ops.wipe()
    return (disp, time.perf_counter() - t0, ok,
            f"{steps} load steps, prestrain {PRESTRAIN:g} released, BandSPD")
