"""The solver task of the design search's wave stage (`printgen.search.waves`): one design's
model swept as the verification sweeps it (its sensors, its mounting, its load case), on its
meshes `coarsen` times coarser (`SceneOptions.coarsen`: the same membrane stiffness, the waved
strands' own curve), read at the flume's points against the search's one prototype sweep.
The task lives here because the verification stage sits above the search stage; the stage's
sweeps of one solver graph run in one worker job, warm-started from each other
(`printgen.search.nets.SolverBatch`)."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

from printgen.errors import SolverError
from printgen.search.nets import SolverBatch, VerifyShared
from printgen.search.waves import Trial, WaveTask, point_errors, screen_levels


def wave_batch(shared: VerifyShared, batch: SolverBatch) -> list[Trial]:
    """Sweep each of `batch`'s tasks (nets of one solver graph; a worker job: pure,
    module-level), each load level of a later sweep also started from the earlier sweeps'
    load steps to it (`sweep`'s paths: a start, never the answer), each net factorized by
    the backend of a load path (`solver.driver.path_backend`, as every sweep). On its own net
    (`coarsen` 1) at the search's levels, with its deformation mismatch; coarser, at the
    stage's screening levels. A sweep the solver refuses (too few levels, sensor wires folding
    over a soft net) is a trial without readings, its reason in `note`."""
    from threadpoolctl import threadpool_limits

    from printgen.run.search import Earlier, _serial

    earlier = Earlier()  # the earlier sweeps' states
    out = []
    with _serial(), threadpool_limits(limits=1):  # one BLAS thread: the same sums everywhere
        for task in batch.tasks:
            trial, states = _trial(shared, task, earlier.paths)
            earlier.add(states)
            out.append(trial)
    return out


def wave_task(shared: VerifyShared, task: WaveTask) -> Trial:
    """`wave_batch` of one task alone (a cold sweep)."""
    return wave_batch(shared, SolverBatch((task,)))[0]


def _trial(shared: VerifyShared, task: WaveTask, paths: Any
           ) -> tuple[Trial, dict[float, Any]]:
    """One task's trial and its sweep's converged states (none when the solver refused)."""
    from printgen.run.search import search_levels
    from printgen.scene.options import SceneOptions, build_scene
    from printgen.verification.preprint import sensor_force, sweep, verify_plan

    p, d = shared.prototype, task.design
    own = task.coarsen == 1
    lv = search_levels(shared) if own else screen_levels()
    force = sensor_force(p)
    trial = Trial(d.net, sensor_force_n=force, coarsen=task.coarsen)
    proto = shared.prototype_run
    plan = verify_plan(p, d, lv=lv, sensors=False,
                       prototype=None if proto is None else proto.scene)
    if proto is None:
        fn, args, kw = plan.jobs()[1]
        proto = fn(*args, **kw)
    ms = plan.ms if own else build_scene(d, SceneOptions(
        mounting=plan.ms.mounting, load=plan.case, sensor_force=force, coarsen=task.coarsen))
    try:
        model = sweep(ms, plan.lv, paths=paths, keep_states=True,
                      **plan.kw_m)
    except SolverError as e:
        return dataclasses.replace(trial, note=str(e)), {}
    md, pd = model.deformation, proto.deformation
    errors = point_errors(md.levels, md.values, pd.levels, pd.values)
    mismatch = math.nan
    if own:
        v = plan.verified(model, proto)
        mismatch = math.sqrt(sum(m.rms_rel**2 for m in v.mismatches) / len(v.mismatches))
    return dataclasses.replace(trial, errors=errors, mismatch=mismatch), model.states
