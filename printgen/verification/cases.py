"""The other load cases of `make --loads`: each one's nominal prototype and model swept at the
case's own levels (no band), what the case used at each level, and the verification with
them (`with_cases`). printgen.verification.pooled runs their sweeps on the verification's pool.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from printgen.barrier.loads import distinct_specs, get_load
from printgen.inputs.prototype import Prototype
from printgen.scaling.record import Design
from printgen.verification.preprint import (
    Run,
    Verification,
    VerifyPlan,
    barriers,
    levels,
    run_jobs,
    stated,
)


@dataclass(frozen=True)
class CaseRuns:
    """One more load case's nominal sweeps (`make --loads`): the prototype and the model at
    the case's own levels (the usual ones when it has none), and what it used at each."""

    spec: str
    prototype: Run
    model: Run
    load: dict[str, Any]

    def to_record(self) -> dict[str, Any]:
        return {"spec": self.spec, "load": self.load,
                "assumptions": [dict(zip(("what", "value", "source"), a, strict=True))
                                for a in self.model.scene.assumptions
                                if a[0].startswith("loading")],
                "model_levels": self.model.deformation.levels,
                "not_converged": {"prototype": self.prototype.failed,
                                  "model": self.model.failed}}


def case_plan(p: Prototype, d: Design, load: str, mounting: str | None = None) -> VerifyPlan:
    """The nominal sweeps of load case `load` at its own levels (the usual ones when it has
    none)."""
    case, kw_p, kw_m, ps, ms = barriers(p, d, load, mounting)
    own = case.levels_for(ms, kw_m["site"])
    lv = levels() if own is None else np.asarray(own, dtype=float)
    return VerifyPlan(case, kw_p, kw_m, ps, ms, lv)


def case_runs(p: Prototype, d: Design, load: str, mounting: str | None = None,
              runs: tuple[Run, Run] | None = None) -> CaseRuns:
    """The nominal prototype and model of load case `load` at its own levels (no band);
    `runs`: its (model, prototype) sweeps already run (`case_plan(...).jobs()`)."""
    plan = case_plan(p, d, load, mounting)
    model, proto = runs if runs is not None else run_jobs(plan.jobs())
    (proto, model), rec = stated(plan.case, (proto, model),
                                 (plan.kw_p["site"], plan.kw_m["site"]))
    return CaseRuns(plan.case.spec, proto, model, rec)


def other_cases(loads: tuple[str, ...] | list[str], own: str) -> list[str]:
    """The specs of `loads` (`make --loads`) but `own`, the verification's, once each."""
    return [s for s in distinct_specs(loads) if s != own]


def with_cases(v: Verification, p: Prototype, d: Design, loads: tuple[str, ...] | list[str],
               runs: dict[str, tuple[Run, Run]] | None = None) -> Verification:
    """`v` with the sweeps of each load case of `loads` (`make --loads`): the verification's
    own case reuses its runs, every other one sweeps its nominal barriers (`case_runs`;
    `runs`: spec -> its sweeps, already run)."""
    if not loads:
        return v
    mounting = v.model.scene.mounting
    out = {}
    for spec in distinct_specs(loads):
        if spec == v.load.get("spec"):
            out[get_load(spec).name] = CaseRuns(spec, v.prototype, v.model, v.load)
        else:
            out[get_load(spec).name] = case_runs(p, d, spec, mounting, (runs or {}).get(spec))
    return dataclasses.replace(v, by_load=out)
