"""The verification's sweeps on one set of workers (printgen.executor.local.shared_pool): `verify`'s
nominal pair, the band's refinement test and variants (printgen.verification.bands) and the
steel counter-example, each started as soon as what it needs is known, so that no core waits
for a pool to finish or for a serial step.

Order of the jobs (the pool takes them first come, first served): the model and the prototype
(longest first), the prototype with its sensors scaled (when they pull too much), the band's
first refinement sweep (on the net COARSENINGS[0] times coarser, at the pair's levels: run
again should a level fail on either barrier, since the band keeps only the levels both
reached); once the pair is done, the prototype's variants (their slack one is the longest sweep
of both examples: started early, it ends with the others) and the counter-example; the model
band's variants (longest first) once the nominal sweeps and the refinement sweep are done; then
the nominal pairs of the other load cases of `make --loads`, which fill the cores the band's
last variants leave idle. The results are those of `verify` (its pair keeping their states),
`model_band` and `with_cases`, byte for byte: the same sweeps on the same nets at the same
levels, from the same starts.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from concurrent.futures import Future

from printgen.barrier.loads import LoadCase
from printgen.executor.local import collect, shared_pool
from printgen.inputs.prototype import Prototype
from printgen.scaling.record import Design
from printgen.scene.options import SceneOptions
from printgen.trace import span
from printgen.verification.bands import (
    COARSENINGS,
    Band,
    meshable,
    model_band,
    prototype_band,
    prototype_jobs,
    run_variant,
)
from printgen.verification.cases import case_plan, other_cases, with_cases
from printgen.verification.decide import decide
from printgen.verification.preprint import Verification, steel_counterexample, verify_plan
from printgen.verification.sensors import scene_sensor_force
from printgen.verification.variants import Variant


def verify_with_band(p: Prototype, d: Design, *, load: str | LoadCase | None = None,
                     counterexample: bool = False, free_section: float | None = None,
                     meanwhile: Callable[[], object] | None = None,
                     loads: tuple[str, ...] = (),
                     alongside: Callable[[Verification, int], object] | None = None
                     ) -> tuple[Verification, Band]:
    """`verify(p, d, load=load, counterexample=...)` and the model's uncertainty band around
    its model run (`model_band`), the prototype's (`prototype_band`, kept on the
    verification with the bands' three-valued verdict, `decide`), on one pool, with the
    nominal sweeps of each other load case of `loads` (`with_cases`; queued behind the band's
    variants); `meanwhile` is called here once the first sweeps have started (this process
    then only waits); `alongside` with the nominal verification (its band not decided yet)
    and the band's coarsening once the band's variants are started: work that needs them
    (make's advice) runs here while they run, its own sweeps queued behind them."""
    plan = verify_plan(p, d, load=load)
    base = Variant(options=SceneOptions(mounting=plan.ms.mounting,
                                        sensor_force=scene_sensor_force(plan.ms)))
    first = COARSENINGS[0]
    cases: dict[str, list[Future]] = {}
    with shared_pool() as pool:

        def behind_variants(coarsen: int) -> None:  # the other cases' sweeps, `alongside`
            for spec in other_cases(loads, plan.case.spec):
                cases[spec] = [pool.submit(fn, *args, **kw) for fn, args, kw
                               in case_plan(p, d, spec, plan.ms.mounting).jobs()]
            if alongside is not None:
                alongside(nominal, coarsen)

        pair = [pool.submit(fn, *args, **kw) for fn, args, kw in plan.jobs(keep_states=True)]
        loaded = [pool.submit(fn, *args, **kw) for fn, args, kw in plan.sensor_jobs()]
        ahead = ({first: pool.submit(run_variant, d, base, plan.lv, first, plan.kw_m)}
                 if meshable(d, first) else {})
        if meanwhile is not None:
            meanwhile()
        with span("verify: nominal sweeps"):
            model, proto = collect(pair)
            # the prototype's variants start as soon as the pair is done (the loaded
            # prototype's sweep plays no part in them), ahead of the counter-example: their
            # slack one is the longest sweep of both examples, the counter-example short and
            # needed last
            theirs = [pool.submit(fn, *args, **kw) for fn, args, kw
                      in prototype_jobs(p, plan.compared(model, proto)[0][0], plan.kw_p)]
            ce = pool.submit(steel_counterexample, d.scale) if counterexample else None
            v = plan.verified(model, proto, None, collect(loaded)[0] if loaded else None)
            nominal = v
        with span("verify: band"):
            band = model_band(d, v.model, load_kw=plan.kw_m, free_section=free_section,
                              ahead=ahead, then=behind_variants)
            pband = prototype_band(p, v.prototype, collect(theirs))
            v = dataclasses.replace(v, decision=decide(v.prototype.deformation.values, band,
                                                       pband), prototype_band=pband)
        if ce is not None:
            v = dataclasses.replace(v, counterexample=collect([ce])[0])
        runs = {spec: tuple(collect(f)) for spec, f in cases.items()}
    return with_cases(v, p, d, loads, runs), band
