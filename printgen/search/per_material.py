"""Per material: the best screened net, the first one on target, and the scales where the
target becomes reachable.

"On target" is the design search's criterion: printable (every constraint met, so the
safety factor is at least `MIN_SAFETY_FACTOR` at the overflow strand force) and the
small-strain membrane stiffness within +-`SMALL_STRAIN_TOLERANCE` of the prototype's. "First"
is the lowest screening score among those (the score of the search, with its datasheet
penalty). A material whose law rests on a datasheet modulus is flagged: its printed value
must be measured on the test pieces before the barrier is printed.
"""

from __future__ import annotations

from printgen.scaling.selection import CALIBRATE_FIRST, MIN_SAFETY_FACTOR
from printgen.search.choice import SMALL_STRAIN_TOLERANCE, closest_key, near_target, rank_key, short
from printgen.search.screen import Screened


def on_target(s: Screened) -> bool:
    return s.feasible and near_target(s)


def per_material(screened: tuple[Screened, ...] | list[Screened]) -> list[dict]:
    """One JSON-ready row per material, in search order: candidates, printable ones, the best
    (lowest score), the first on target and the printable one closest to the target."""
    rows = []
    for mat in dict.fromkeys(s.point.material for s in screened):
        mine = [s for s in screened if s.point.material == mat]
        ok = [s for s in mine if s.feasible]
        hits = [s for s in ok if on_target(s)]
        rows.append({
            "material": mat, "candidates": len(mine), "feasible": len(ok),
            "on_target": len(hits),
            "datasheet": any(s.datasheet for s in mine),
            "best": min(ok, key=rank_key).to_record() if ok else None,
            "first_on_target": min(hits, key=rank_key).to_record() if hits else None,
            "closest": min(ok, key=closest_key).to_record() if ok else None,
        })
    return rows


def first_on_target(screened: tuple[Screened, ...] | list[Screened]) -> Screened | None:
    """The lowest-score net of any material that is on target, or None."""
    hits = [s for s in screened if on_target(s)]
    return min(hits, key=rank_key) if hits else None


def target_sentence(screened: tuple[Screened, ...] | list[Screened]) -> list[str]:
    """Sentences for the design's reasons: the first on-target net, or that there is none."""
    s = first_on_target(screened)
    tol = f"+-{SMALL_STRAIN_TOLERANCE:.0%} at safety factor >= {MIN_SAFETY_FACTOR}"
    if s is None:
        return [f"no material gives a printable net within {tol}"]
    out = [(f"first net within {tol}: {short(s)} ({s.error_small:+.0%}, safety factor "
            f"{s.safety_factor:.1f}, law from {s.law_source})")]
    if s.datasheet:
        out.append(f"it rests on a DATASHEET value of {s.point.material.upper()}: "
                   + CALIBRATE_FIRST)
    return out


def reachable(records: list[dict]) -> list[dict]:
    """Across a scale series (records of `result_record`, each with "per_material"): per
    material, the scales at which some net is on target, and the lowest and highest."""
    by: dict[str, list[float]] = {}
    for rec in records:
        for row in rec.get("per_material", []):
            by.setdefault(row["material"], [])
            if row["on_target"]:
                by[row["material"]].append(rec["scale"])
    return [{"material": m, "scales_on_target": sc,
             "scale_range": [min(sc), max(sc)] if sc else None} for m, sc in by.items()]
