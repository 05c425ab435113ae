"""This machine's speed, for the run's estimate (printgen.run.budget): the CPU time of a small
fixed solve here over its CPU time on the machine budget.py's constants were measured on.

The constants of budget.py are CPU seconds on one machine; a laptop, a lab's desktop or a CI
runner may be several times faster or slower (benchmarks/measurements.md#speed-reference:
constants fitted on one machine estimated a run three times too long on another). The workload
timed here is the solver's own (scene simple-pinned at 61 x 21 nodes, barrier-physics.md
section 7, solved at the tolerance its reference time was measured at): the sweeps are most of
a run's time, and the parts' steps are numpy and Python work of the same kind. It is timed as
CPU of this process (`time.process_time`), best of CALIBRATION_REPEAT after one untimed solve
(imports and first-call costs), so that other processes on a shared machine barely change it:
the estimate stays what the run costs on this machine, and a loaded machine is not refused for
its load. Assumption stated: every step of a run scales with the machine as this solve does.
"""

from __future__ import annotations

import functools
import math
import os
import time

from printgen.errors import InputError

CALIBRATION_REPEAT = 3  # timed solves (the best kept) after one untimed
CALIBRATION_TOL = 1e-6  # the tolerance REFERENCE_CPU_S was measured at (bench solver's GOAL_TOL;
# not the verification's SOLVER_TOL, 1e-7: the reference time is bench solver's)
# CPU of the calibration solve on the machine budget.py's constants were measured on: bench
# solver's 61 x 21 solve at tol 1e-6 there (benchmarks/measurements.md#speed-reference)
REFERENCE_CPU_S = 0.050
SPEED_ENV = "PRINTGEN_SPEED"  # a fixed factor instead of the measured one (benchmarks, tests)


def calibration_cpu() -> float:
    """CPU seconds of the calibration solve on this machine (best of CALIBRATION_REPEAT)."""
    from printgen.solver import solve
    from printgen.solver.scenes import simple_scene

    scene = simple_scene(refine=1)
    best = math.inf
    for k in range(CALIBRATION_REPEAT + 1):
        t = time.process_time()
        result = solve(scene.net, scene.loads_at(1.0), tol=CALIBRATION_TOL)
        if k:
            best = min(best, time.process_time() - t)
        if not result.converged:  # the solver's own scene: a failure is a broken install
            raise RuntimeError(f"calibration solve did not converge: {result.reason}")
    return best


@functools.lru_cache(maxsize=1)
def speed_factor() -> float:
    """This machine's time over the reference machine's (2: twice as slow), measured once per
    process; PRINTGEN_SPEED, when set, gives it instead."""
    given = os.environ.get(SPEED_ENV)
    if given is not None:
        try:
            value = float(given)
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and value > 0):
            raise InputError(f"{SPEED_ENV}={given!r} must be a positive number (this machine's "
                             "time over the reference machine's, e.g. 1 or 2.5); unset it to "
                             "measure it")
        return value
    return max(calibration_cpu(), 1e-6) / REFERENCE_CPU_S
