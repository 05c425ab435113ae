"""The scale series' table and what it answers: each case normalised by the prototype's own
deformation, the range of lambda over which a material keeps similitude, and the check of the
linear rows against the (F / EA)^(1/3) law of a pure elastic net.

The law: a pretension-free net of linear, tension-only strands under a transverse load F per
node deflects by w with F ~ EA (w / L)^3 when w << L (the strands' stretch grows as the square
of their rotation), so every normalised deformation goes as Pi^(1/3) with Pi = F / EA; here
F = rho g h_B A* (the bed node's load at full head) and EA the net strands' initial stiffness.
Anchored at the prototype: law(row, lambda) = prototype x (Pi / Pi_prototype)^(1/3).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from printgen.verification.series import OUTPUTS, CaseResult, Row, SeriesShared

TOLERANCE = 0.10  # "keeps similitude": within +-10 % of the prototype (the brief's sentence)
LAW_EXPONENT = 1.0 / 3.0  # pure elastic net: w / L ~ (F / EA)^(1/3)
LAW_METRICS = ("deflection", "lowering")  # the law is read on the net's out-of-plane shape
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
        law = {k: ref.values[k] * (pi / pi0) ** LAW_EXPONENT for k in LAW_METRICS}
        points.append(Point(r.row, r.scale, r.values,
                            {k: _ratio(v, ref.values[k]) for k, v in r.values.items()}, pi,
                            law, {k: _ratio(r.values[k], law[k]) - 1.0 for k in LAW_METRICS},
                            r.hold_share, r.iterations, r.failed))
    s = Series(shared.prototype.name, scene, scales, shared.rows, points, dict(ref.values))
    for row in shared.rows:
        if row.kind != "similitude":
            s.sentences[row.key] = sentence(s, row, pi0)
            s.law[row.key] = law_check(s, row, shared.net.slack)
    return s


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


def sentence(s: Series, row: Row, pi0: float) -> str:
    """"PETG keeps deflection within +-10 % of the prototype for lambda from A to B", with
    the lowering's range and the law's estimate of where the material is exact."""
    pts = [s.point(row.key, lam) for lam in s.scales]
    defl = in_band([(p.scale, p.ratio["deflection"]) for p in pts])
    low = in_band([(p.scale, p.ratio["lowering"]) for p in pts])
    text = (f"{row.short} keeps deflection within +-{TOLERANCE:.0%} of the prototype "
            f"{_runs_text(defl)} (lowering: {_runs_text(low)})")
    # Pi of a material row goes as 1 / lambda: Pi(lambda) = Pi(1) / lambda (one point gives it)
    p = pts[0]
    exact = p.pi * p.scale / pi0
    lo, hi = exact / (1 + TOLERANCE) ** 3, exact / (1 - TOLERANCE) ** 3
    return (text + f"; by the (F/EA)^(1/3) law it is exact at lambda = {exact:.3g} and within "
            f"+-{TOLERANCE:.0%} for lambda from {lo:.3g} to {hi:.3g}.")


def law_check(s: Series, row: Row, slack: float) -> dict[str, Any]:
    """The row against the (F/EA)^(1/3) law: departures, the exponent between neighbouring
    scales, and why it departs (in words, with the numbers)."""
    pts = [s.point(row.key, lam) for lam in s.scales]
    dep = {k: [p.departure[k] for p in pts] for k in LAW_METRICS}
    slopes = [math.log(b.values["deflection"] / a.values["deflection"]) / math.log(b.pi / a.pi)
              for a, b in zip(pts, pts[1:], strict=False) if b.pi != a.pi]
    worst = max(pts, key=lambda p: abs(p.departure["deflection"]))
    size = max(abs(worst.values["deflection"]), abs(worst.values["lowering"]),
               abs(s.reference["deflection"]), abs(s.reference["lowering"]))
    why = [f"largest departure {worst.departure['deflection']:+.1%} (deflection) at lambda = "
           f"{worst.scale:g}, where the net deflects {worst.values['deflection']:.3f} x width "
           f"and its top lowers {worst.values['lowering']:.3f} x height against the prototype's "
           f"{s.reference['deflection']:.3f} / {s.reference['lowering']:.3f}"]
    if size > SMALL:
        why.append("the law is the small-deflection limit of a pretension-free net: with "
                   "deformations of this size the strands' rotations are not small, the free "
                   "top edge sags and the water at the current node height loads the lowered "
                   "nodes more, so the exponent differs from 1/3")
    hold = max(p.hold_share for p in pts)
    why.append(f"the hold of unloaded nodes carries at most {hold:.2%} of the load (its "
               "stiffness follows the load, lambda^-2, not EA, so it is a share that changes "
               "with E)")
    why.append(f"no pretension; initial slack {slack:.1%}"
               + (" (slack is a length: it delays the response and breaks the power law)"
                  if slack else ""))
    return {"exponent": LAW_EXPONENT, "departure": dep, "local_exponents": slopes,
            "max_abs_departure": max(abs(v) for v in dep["deflection"] + dep["lowering"]),
            "explanation": why}
