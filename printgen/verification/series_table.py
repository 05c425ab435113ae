"""The scale series' table and what it answers: each case normalised by the prototype's own
deformation, the range of lambda over which a material keeps similitude, and the check of the
linear rows against the (F / EA)^(1/3) law of a pure elastic net.

The law: a pretension-free net of linear, tension-only strands under a transverse load F per
node deflects by w with F ~ EA (w / L)^3 when w << L (the strands' stretch grows as the square
of their rotation), so the normalised deflection goes as Pi^(1/3) with Pi = F / EA, and the
strains (the mid-height elongation) as (w / L)^2 ~ Pi^(2/3); here F = rho g h_B A* (the bed
node's load at full head) and EA the net strands' initial stiffness. Anchored at the
prototype: law(row, lambda) = prototype x (Pi / Pi_prototype)^exponent. The lowering of a free
top edge has no single exponent: the bulged net's shortening goes as Pi^(2/3), the top edge's
own sag, as a cable pulled down by the vertical strands, as Pi^(1/3); its local exponents are
reported and expected between the two.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any

from printgen.verification.series import OUTPUTS, CaseResult, Row, SeriesShared

TOLERANCE = 0.10  # "keeps similitude": within +-10 % of the prototype (the brief's sentence)
# pure elastic net: w / L ~ (F / EA)^(1/3), strains ~ (w / L)^2
LAW_EXPONENTS = {"deflection": 1.0 / 3.0, "strain_mid": 2.0 / 3.0}
LOWERING_BRACKET = (1.0 / 3.0, 2.0 / 3.0)  # the free top edge's lowering: between the two
BRACKET_SLACK = 0.02  # exponents read from finite steps: the bracket's edges +- this
SMALL = 0.05  # a deformation below this (5 % of the size) is "small" for the law's limit


@dataclass(frozen=True)
class Point:
    """One (row, lambda): the OUTPUTS, their ratio to the prototype's, Pi = F / EA, the law's
    prediction and the departure from it (value / law - 1)."""

    row: str
    scale: float
    values: dict[str, float]
    ratio: dict[str, float]
    pi: float
    law: dict[str, float]
    departure: dict[str, float]
    hold_share: float
    iterations: int
    failed: dict[float, str]

    def to_record(self) -> dict[str, Any]:
        return {"row": self.row, "scale": self.scale, "values": self.values,
                "ratio_to_prototype": self.ratio, "pi_f_over_ea": self.pi,
                "law": self.law, "law_departure": self.departure,
                "hold_share": self.hold_share, "iterations": self.iterations,
                "not_converged": self.failed}


@dataclass
class Series:
    """A solved scale series and what it answers."""

    prototype: str
    scene: str
    scales: tuple[float, ...]
    rows: tuple[Row, ...]
    points: list[Point]
    reference: dict[str, float]
    sentences: dict[str, str] = field(default_factory=dict)
    law: dict[str, dict[str, Any]] = field(default_factory=dict)
    assumptions: list[tuple[str, str, str]] = field(default_factory=list)
    record_extra: dict[str, Any] = field(default_factory=dict)

    def point(self, row: str, scale: float) -> Point:
        return next(p for p in self.points if p.row == row and p.scale == scale)

    def to_record(self) -> dict[str, Any]:
        return {"prototype": self.prototype, "scene": self.scene, "scales": self.scales,
                "rows": [r.to_record() for r in self.rows],
                "outputs": OUTPUTS, "prototype_values": self.reference,
                "tolerance": TOLERANCE, "points": [p.to_record() for p in self.points],
                "sentences": self.sentences, "law_check": self.law,
                "assumptions": [dict(zip(("what", "value", "source"), a, strict=True))
                                for a in self.assumptions], **self.record_extra}


def summarise(shared: SeriesShared, scales: tuple[float, ...],
              results: list[CaseResult], scene: str) -> Series:
    """The Series of `results` (every case of `scales`, and the prototype at lambda = 1)."""
    ref = next(r for r in results if r.row == "unscaled" and r.scale == 1.0)
    pi0 = ref.node_load / ref.ea
    points = []
    for r in results:
        if r.scale not in scales:
            continue  # the prototype, solved as the reference only
        pi = r.node_load / r.ea
        law = {k: ref.values[k] * (pi / pi0) ** e for k, e in LAW_EXPONENTS.items()}
        points.append(Point(r.row, r.scale, r.values,
                            {k: _ratio(v, ref.values[k]) for k, v in r.values.items()}, pi,
                            law, {k: _ratio(r.values[k], law[k]) - 1.0 for k in LAW_EXPONENTS},
                            r.hold_share, r.iterations, r.failed))
    s = Series(shared.prototype.name, scene, scales, shared.rows, points, dict(ref.values))
    for row in shared.rows:
        if row.kind != "similitude":
            s.sentences[row.key] = sentence(s, row, pi0, pure_net(shared))
            s.law[row.key] = law_check(s, row, shared.net.slack, pure_net(shared))
    return s


def pure_net(shared: SeriesShared) -> bool:
    """Linear net strands, no border cables and no pulling sensors: the law's own case."""
    p = shared.prototype
    return p.net.panel_law is None and p.border is None and not shared.net.sensors


def _ratio(a: float, b: float) -> float:
    return a / b if b else math.nan


def in_band(values: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """The runs (first, last lambda) of consecutive scales whose ratio is within TOLERANCE."""
    runs: list[list[float]] = []
    prev_ok = False
    for lam, ratio in values:
        ok = abs(ratio - 1.0) <= TOLERANCE
        if ok and prev_ok:
            runs[-1][1] = lam
        elif ok:
            runs.append([lam, lam])
        prev_ok = ok
    return [(a, b) for a, b in runs]


def _runs_text(runs: list[tuple[float, float]]) -> str:
    if not runs:
        return "at no lambda in the series"
    parts = [f"lambda = {a:g}" if a == b else f"lambda from {a:g} to {b:g}" for a, b in runs]
    return "for " + " and ".join(parts)


def sentence(s: Series, row: Row, pi0: float, pure: bool) -> str:
    """"PETG keeps deflection within +-10 % of the prototype for lambda from A to B", with
    the lowering's range and the law's estimate of where the material is exact."""
    pts = [s.point(row.key, lam) for lam in s.scales]
    defl = in_band([(p.scale, p.ratio["deflection"]) for p in pts])
    low = in_band([(p.scale, p.ratio["lowering"]) for p in pts])
    text = (f"{row.short} keeps deflection within +-{TOLERANCE:.0%} of the prototype "
            f"{_runs_text(defl)} (lowering: {_runs_text(low)})")
    if not pure:
        return text + " (no law estimate: the scene is not a pure elastic net)."
    # Pi of a material row goes as 1 / lambda: Pi(lambda) = Pi(1) / lambda (one point gives it)
    p = pts[0]
    exact = p.pi * p.scale / pi0
    lo, hi = exact / (1 + TOLERANCE) ** 3, exact / (1 - TOLERANCE) ** 3
    if exact < 1.0:
        return (text + f"; it is stiffer than the prototype at every lambda >= 1 (the "
                f"(F/EA)^(1/3) law would match it at lambda = {exact:.3g}).")
    return (text + f"; the (F/EA)^(1/3) law puts it exact at lambda = {exact:.3g} and within "
            f"+-{TOLERANCE:.0%} from lambda = {lo:.3g} to {hi:.3g}.")


def local_exponents(pts: list[Point], key: str) -> list[float]:
    """d ln(value) / d ln(Pi) between neighbouring scales of one row."""
    return [math.log(b.values[key] / a.values[key]) / math.log(b.pi / a.pi)
            for a, b in itertools.pairwise(pts)
            if b.pi != a.pi and a.values[key] > 0 and b.values[key] > 0]


def law_check(s: Series, row: Row, slack: float, pure: bool) -> dict[str, Any]:
    """The row against the (F/EA)^(1/3) law: departures, the local exponents between
    neighbouring scales, and why it departs (in words, with the numbers). `pure`: the scene is
    a pure elastic net (linear strands, no border cables, no pulling sensors)."""
    pts = [s.point(row.key, lam) for lam in s.scales]
    dep = {k: [p.departure[k] for p in pts] for k in LAW_EXPONENTS}
    slopes = {k: local_exponents(pts, k) for k in (*LAW_EXPONENTS, "lowering")}
    worst = max(pts, key=lambda p: abs(p.departure["deflection"]))
    size = max(abs(worst.values["deflection"]), abs(worst.values["lowering"]),
               abs(s.reference["deflection"]), abs(s.reference["lowering"]))
    why = [(f"largest deflection departure {worst.departure['deflection']:+.1%} at lambda = "
           f"{worst.scale:g}, where the net deflects {worst.values['deflection']:.3f} x width "
           f"and its top lowers {worst.values['lowering']:.3f} x height (prototype: "
           f"{s.reference['deflection']:.3f} / {s.reference['lowering']:.3f})")]
    if not pure:
        why.append("not a pure elastic net (border cables sliding, a non-linear panel law or "
                   "sensor wires pulling a force that does not scale): the law is only a guide")
    if size > SMALL:
        why.append("the law is the small-deflection limit: with deformations of this size the "
                   "strands' rotations are not small and the water at the current node height "
                   "loads the lowered nodes more, so the exponents move away from 1/3 and 2/3")
    lo, hi = LOWERING_BRACKET
    inside = all(lo - BRACKET_SLACK <= e <= hi + BRACKET_SLACK for e in slopes["lowering"])
    why.append("lowering exponents " + ", ".join(f"{e:.3f}" for e in slopes["lowering"])
               + (" lie" if inside else " do not lie") + " between 1/3 (the free top edge sags as "
               "a cable pulled by the vertical strands) and 2/3 (the bulged net's shortening)")
    hold = max(p.hold_share for p in pts)
    why.append(f"the hold of unloaded nodes carries at most {hold:.2%} of the load (its "
               "stiffness follows the load, lambda^-2, not EA)")
    why.append(f"no pretension; initial slack {slack:.1%}"
               + (" (a length that delays the response: it breaks the power law)"
                  if slack else ""))
    return {"exponents": LAW_EXPONENTS, "lowering_bracket": LOWERING_BRACKET,
            "departure": dep, "local_exponents": slopes, "pure_elastic_net": pure,
            "max_abs_departure": max(abs(v) for d in dep.values() for v in d),
            "lowering_in_bracket": inside, "explanation": why}
