"""JSON records of a design search: the summary (report.json) and every candidate as a table.

Nothing here depends on where the search ran (serial, local cluster, remote scheduler) or on
the clock: the same search gives byte-identical JSON.
"""

from __future__ import annotations

import json
from collections import Counter
from typing import Any

from printgen.search.choice import SMALL_STRAIN_TOLERANCE
from printgen.search.nets import SearchResult, VerifyScore
from printgen.search.per_material import per_material
from printgen.search.screen import Screened
from printgen.search.space import space_record

# Columns of the candidate table (candidates.json), in order.
COLUMNS = ("index", "material", "beads_across", "layers", "mesh_x_mm", "mesh_y_mm",
           "border_beads", "membrane_n_per_m", "error_small_strain", "stiffness_error_across",
           "stiffness_error_up", "error_rms_log", "score",
           "safety_factor", "speed_mm_per_s", "opening_mm", "d_pi2", "d_pi3", "print_time_s",
           "feasible", "violations")


def score_record(v: VerifyScore | None) -> dict | None:
    """The solver's verdict as a record."""
    if v is None:
        return None
    return {"mismatch_rms": v.mismatch, "mismatch_per_metric": v.per_metric,
            "max_rel": v.max_rel, "ok": v.ok, "failed_levels": list(v.failed_levels)}


def _with_score(s: Screened, v: VerifyScore | None) -> dict:
    return {**s.to_record(), "verification": score_record(v)}


def result_record(res: SearchResult) -> dict[str, Any]:
    """The search at one scale: chosen net and why, Pareto set, verified nets, select's pick."""
    sc = res.screened
    chosen = None if res.chosen is None else _with_score(sc[res.chosen],
                                                         res.verified.get(res.chosen))
    lower = None
    if res.objective == "deformation" and res.chosen is not None:
        lower = res.verified[res.chosen].mismatch < res.select_score.mismatch
    within = None if res.chosen is None else abs(sc[res.chosen].error_small) <= \
        SMALL_STRAIN_TOLERANCE
    return {
        "prototype": res.prototype, "scale": res.scale, "objective": res.objective,
        "space": space_record(res.space, len(sc)),
        "target_small_strain_n_per_m": sc[0].target_n_per_m if sc else None,
        "small_strain_tolerance": SMALL_STRAIN_TOLERANCE,
        "chosen": chosen, "design": None if res.design is None else res.design.to_dict(),
        "chosen_within_small_strain_tolerance": within,
        "reasons": list(res.reasons), "binding_constraints": list(res.binding),
        "waves": None if res.wave is None else res.wave.to_record(),
        "closest_feasible": None if res.closest is None else sc[res.closest].to_record(),
        "per_material": per_material(sc),
        "select_pick": {**_with_score(res.select_screened, res.select_score),
                        "design": res.select_design.to_dict()},
        "mismatch_lower_than_select": lower,
        "verified": [_with_score(sc[i], v) for i, v in sorted(res.verified.items())],
        "pareto": {"objectives": [_objective_name(res), "abs_d_pi2", "abs_d_pi3",
                                  "print_time_s"],
                   "members": [[i, res.objective_value(i), abs(sc[i].d_pi2), abs(sc[i].d_pi3),
                                sc[i].print_time_s] for i in res.pareto]},
        "counts": {"screened": len(sc), "feasible": sum(s.feasible for s in sc),
                   "verified": len(res.verified),
                   "violations": dict(sorted(Counter(k for s in sc
                                                     for k in {k for k, _ in s.violations})
                                             .items()))},
    }


def _objective_name(res: SearchResult) -> str:
    return "mismatch_rms" if res.objective == "deformation" else "error_rms_log"


def candidate_row(s: Screened) -> list[Any]:
    r = s.to_record()
    r["violations"] = "; ".join(v["reason"] for v in r["violations"])
    return [r[c] for c in COLUMNS]


def candidates_json(results: list[SearchResult]) -> str:
    """Every candidate of every scale: {scale: {columns, rows}}, one row per line
    (deterministic; compact enough for tens of thousands of candidates)."""
    parts = []
    for res in results:
        rows = ",\n".join(json.dumps(candidate_row(s), allow_nan=False)
                          for s in res.screened)
        parts.append(f'"{res.scale:g}": {{"columns": {json.dumps(list(COLUMNS))},\n'
                     f'"rows": [\n{rows}\n]}}')
    return "{\n" + ",\n".join(parts) + "\n}\n"
