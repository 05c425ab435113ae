"""Why the design search chose its net, and which constraints keep it from the target.

The stiffness target is the prototype's membrane stiffness at small strain: a net within
+-`SMALL_STRAIN_TOLERANCE` of it is "on target". When no printable candidate is, the closest
printable one is named with the constraints that bind: what the candidates closer to the target
fail, and the search bounds the closest one sits on.
"""

from __future__ import annotations

from collections import Counter
from typing import TYPE_CHECKING

from printgen.scaling.selection import CALIBRATE_FIRST, MIN_SAFETY_FACTOR, NET_ON_TARGET
from printgen.search.screen import Screened
from printgen.search.space import SearchSpace, half_cell_counts

if TYPE_CHECKING:
    from printgen.search.nets import SearchResult

SMALL_STRAIN_TOLERANCE = NET_ON_TARGET  # on target: small-strain membrane stiffness within +-30 %


def near_target(s: Screened) -> bool:
    """Small-strain membrane stiffness within SMALL_STRAIN_TOLERANCE of the target."""
    return abs(s.error_small) <= SMALL_STRAIN_TOLERANCE


def rank_key(s: Screened) -> tuple:
    """The search's order: screening score, then print time, then search order."""
    return (round(s.score, 12), s.print_time_s, s.point.index)


def closest_key(s: Screened) -> tuple:
    """Closest to the target at small strain first, then search order."""
    return (abs(s.error_small), s.point.index)
LABELS = {"strength": f"strength (safety factor < {MIN_SAFETY_FACTOR} at the overflow force)",
          "print": "printability (bead, layer or flow limits of the printer and material)",
          "bed": "bed size (the panel does not fit the printer)",
          "opening": "mesh opening (clear opening below the minimum)"}


def binding_constraints(screened: list[Screened], space: SearchSpace
                        ) -> tuple[int | None, tuple[str, ...]]:
    """(index of the printable candidate closest to the target at small strain, the
    constraints that keep the search from the target; empty when that candidate is on it)."""
    feasible = [s for s in screened if s.feasible]
    if not feasible:
        return None, tuple(_kinds(screened, f"of the {len(screened)} candidates"))
    best = min(feasible, key=closest_key)
    if near_target(best):
        return best.point.index, ()
    closer = [s for s in screened if abs(s.error_small) < abs(best.error_small)]
    out = _kinds(closer, f"of the {len(closer)} candidates closer to the target")
    out += _bounds(best, space)
    return best.point.index, tuple(out)


def _kinds(cands: list[Screened], what: str) -> list[str]:
    counts = Counter(k for s in cands for k in {k for k, _ in s.violations})
    example: dict[str, str] = {}
    for s in cands:
        for k, reason in s.violations:
            example.setdefault(k, reason)
    return [f"{LABELS[k]}: {n} {what} fail it (e.g. {example[k]})"
            for k, n in sorted(counts.items(), key=lambda kv: (-kv[1], kv[0]))]


def _bounds(best: Screened, space: SearchSpace) -> list[str]:
    """The search bounds `best` sits on in the direction that would bring it closer."""
    p, softer = best.point, best.error_small > 0
    width, height = p.mesh_x_mm * p.half_cells_x / 2, p.mesh_y_mm * p.half_cells_y / 2
    nxs, nys = half_cell_counts(width, space.mesh_x_mm), half_cell_counts(height, space.mesh_y_mm)
    out = []
    if p.half_cells_x == (nxs[0] if softer else nxs[-1]):
        bound = space.mesh_x_mm[1 if softer else 0]
        out.append(f"search bounds: mesh across {p.mesh_x_mm:.4g} mm is the last whole mesh "
                   f"within the {'upper' if softer else 'lower'} bound {bound:.4g} mm "
                   "(widen --mesh-x-mm, at the price of Pi2)")
    if p.half_cells_y == (nys[-1] if softer else nys[0]):
        bound = space.mesh_y_mm[0 if softer else 1]
        out.append(f"search bounds: mesh up {p.mesh_y_mm:.4g} mm is the last whole mesh "
                   f"within the {'lower' if softer else 'upper'} bound {bound:.4g} mm "
                   "(widen --mesh-y-mm, at the price of Pi2)")
    return out


def short(s: Screened) -> str:
    """A candidate net in a table cell: material beads x layers, mesh, border."""
    p = s.point
    return (f"{p.material.upper()} {p.beads_across}x{p.layers}, {p.mesh_x_mm:.4g} x "
            f"{p.mesh_y_mm:.4g} mm, border {p.border_beads}")


def describe(s: Screened) -> str:
    """One phrase naming a candidate net."""
    p = s.point
    return (f"{p.material.upper()} strand of {p.beads_across} bead(s) x {p.layers} layer(s), "
            f"{p.pattern} mesh {p.mesh_x_mm:.4g} x {p.mesh_y_mm:.4g} mm (across x up), border "
            f"{p.border_beads} bead(s)")


def choice_reasons(res: SearchResult) -> list[str]:
    """Sentences explaining the chosen net (or why there is none)."""
    if res.chosen is None:
        return ["no printable net in the search space", *res.binding]
    s = res.screened[res.chosen]
    out = [f"chosen: {describe(s)}"]
    if res.objective == "deformation":
        v, sel = res.verified[res.chosen], res.select_score
        way = "lower" if v.mismatch < sel.mismatch else "NOT lower"
        out.append(f"lowest deformation mismatch of the {len(res.verified)} nets verified by the "
                   f"solver: RMS {v.mismatch:.3f} of the prototype's peak over h/h_B = 0-1.1, "
                   f"{way} than select's pick ({sel.mismatch:.3f})")
    else:
        n_ok = sum(c.feasible for c in res.screened)
        out.append(f"lowest membrane-law error of {n_ok} printable candidates "
                   f"({len(res.screened)} screened): RMS log error {s.error_rms_log:.3f} over "
                   "1-40 % strain (not verified by the solver: --objective deformation does)")
    on = near_target(s)
    out.append(f"membrane stiffness at small strain {s.error_across:+.0%} off the target "
               f"across the barrier and {s.error_up:+.0%} up it (worse: "
               f"{s.membrane_n_per_m:.4g} N/m against {s.target_n_per_m:.4g} N/m): "
               f"{'within' if on else 'outside'} +-{SMALL_STRAIN_TOLERANCE:.0%}")
    if res.closest is not None and res.binding:
        c = res.screened[res.closest]
        out.append(f"no printable net is within +-{SMALL_STRAIN_TOLERANCE:.0%}; the closest is "
                   f"{describe(c)} at {c.error_small:+.0%}; binding constraints: "
                   + "; ".join(res.binding))
    out.append(f"similitude broken: Pi2 (mesh / h_B, the larger of the two diagonals) by "
               f"{s.d_pi2:+.0%}, Pi3 (equal-area strand diameter / h_B) by {s.d_pi3:+.0%}")
    out.append(f"safety factor {s.safety_factor:.2f} at the estimated overflow strand force "
               f"{s.peak_force_n:.3g} N; clear mesh opening {s.opening_mm:.2f} mm; net "
               f"extrusion time about {s.print_time_s / 60:.0f} min at "
               f"{s.speed_mm_per_s:.3g} mm/s")
    if s.datasheet:
        out.append(f"the {s.point.material.upper()} law is from a DATASHEET modulus: printed "
                   f"parts are often 2x softer; {CALIBRATE_FIRST}")
    return out
