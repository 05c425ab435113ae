"""The simple-pinned scene in OpenSeesPy (the `bench` extra), for a side-by-side benchmark.

Corotational trusses (`corotTruss`) of a tension-only material (`Elastic E 0 0`: no
compression stiffness), nodal loads at the initial node height (OpenSees has no load that
follows the node height), Newton with line search under load control, `BandSPD` system. A flat
net without pretension has no out-of-plane stiffness at the start, so each strand gets a small
initial strain (`InitStrainMaterial`, PRESTRAIN) that is released after loading
(`epsInit` -> 0) with one more solve at full load.

Convergence test, the same as printgen's: `NormUnbalance` in the max-norm (nType 0) at
tol x `force_scale`, printgen's force scale (max of the external nodal forces and the strand
tensions, N: `Result.load_norm` of printgen's solve of the same net), so both stop at
max |out-of-balance force| <= 1e-6 of the same number. OpenSees's default (the 2-norm at
tol x max |load|, 1.6 kN at 61 x 21 against printgen's 47 kN scale) asked for about
1e-12 of printgen's scale: 80 iterations instead of 74 (measured at 61 x 21).

What it runs on (measured at 61 x 21, openseespy 3.7.1): one thread. `BandSPD` calls
LAPACK's dpbtrf/dpbtrs from its bundled liblapack on the system's reference BLAS (Debian
`libblas3`, single-threaded); the bundled libgomp starts no thread in this model (the
process's thread count, /proc/self/task, is the same before and after a solve) and is pinned
to one thread by threadpoolctl anyway (`threadpool_limits(1)` reaches it: it is listed as
"openmp" once openseespy is imported). Of the systems tried only BandSPD and BandGeneral
converge here (ProfileSPD, SparseSYM, SparseGEN, UmfPack fail at the first step); Newton
and KrylovNewton without line search fail too.

Sensitivity to STEPS (same test): 1 step 40 iterations (~0.5 of the 10-step time), 2 or 3
steps fail at the first step, 5 steps 58, 10 steps 74. The first loaded step costs ~40
iterations whatever the step (the flat net's start), each later step 3-5.
"""

from __future__ import annotations

import time

import numpy as np

PRESTRAIN = 1e-6  # initial tension strain that lets OpenSees factorize the flat net's tangent
STEPS = 10  # load steps: the robust choice (2 and 3 steps fail at 61 x 21, see above)
NORM_MAX = 0  # NormUnbalance nType: 0 = max-norm (printgen's test), 2 = 2-norm (the default)


def solve_opensees(nodes, fixed, elements, ea, loads, *, force_scale: float | None = None,
                   steps: int = STEPS, tol: float = 1e-6, max_iter: int = 100):
    """Displacements (n, 3) m, wall seconds, converged, note, CPU seconds (process_time).

    force_scale : N, the force the tolerance is relative to (printgen's `load_norm`);
    default max |load| (then the test is stricter than printgen's)."""
    import openseespy.opensees as ops

    t0, c0 = time.perf_counter(), time.process_time()
    scale = float(np.abs(loads).max()) if force_scale is None else float(force_scale)
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
    ops.test("NormUnbalance", tol * scale, max_iter, 0, NORM_MAX)
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
    note = (f"{steps} load steps, prestrain {PRESTRAIN:g} released, BandSPD, max-norm test "
            f"at {tol:g} x {scale:.4g} N")
    return disp, time.perf_counter() - t0, ok, note, time.process_time() - c0
