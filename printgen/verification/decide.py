"""The three-valued verdict of prototype vs printed model from their bands: PASS when every
combination within both central intervals keeps every quantity within the tolerance, FAIL
when none does, UNDECIDED when the bands straddle it (some weighted inputs pass, others fail).
An UNDECIDED verdict names the uncertainty that decides (the variants whose move alone crosses
the tolerance, else the one that moves the reading most) and the cheapest lab test that
settles it (`printgen.verification.variants.TESTS`). The flume's capacity is the caller's
(`printgen.verification.preprint.Verification.verdict`: a test the flume cannot run fails).

The two nets' initial slack is one input, not two (`paired_slack`): slack is a length ratio,
and geometric similitude has the model hung with the prototype's relative slack, whatever it
is; so the verdict compares the model with 1 % slack against the prototype with 1 % slack,
never one net slack against the other taut. How closely a lab matches the prototype's sag is
not modelled (the cheapest test that settles the slack still names it).

A weighted input under which the solver refuses the model (`Band.refused`: its sensor wires
fold the net, say) has no curves to compare; the test cannot run as designed under it, so the
verdict is not PASS while it is plausible: a PASS of the others becomes UNDECIDED, decided by
that input (a FAIL stays FAIL).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from printgen.verification.bands import Band
from printgen.verification.compare import METRICS, TOLERANCE
from printgen.verification.measured import Measurement
from printgen.verification.variants import settling_tests

VERDICTS = ("PASS", "FAIL", "UNDECIDED")


@dataclass(frozen=True)
class MetricDecision:
    """One quantity: `status` (a VERDICTS value), the largest (`worst`) and smallest (`best`)
    mismatch any pair within the two central intervals can have at some level (fraction of
    the prototype's peak), and the variants whose move alone crosses the tolerance."""

    metric: str
    status: str
    worst: float
    best: float
    deciding: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class Decision:
    """The verdict of the bands: per quantity, overall, and for UNDECIDED the deciding
    variants, their questions and the tests that settle them, cheapest first (`test`)."""

    verdict: str
    metrics: list[MetricDecision]
    deciding: list[str]
    questions: list[str]
    tests: list[str]
    tolerance: float = TOLERANCE
    assumptions: list[str] = field(default_factory=list)  # how the bands were compared
    refused: dict[str, str] = field(default_factory=dict)  # deciding inputs the solver refused

    @property
    def test(self) -> str:
        """The cheapest test that settles a deciding question ("" when none decides)."""
        return self.tests[0] if self.tests else ""

    def sentence(self) -> str:
        """The verdict's sentence for UNDECIDED (empty otherwise)."""
        if self.verdict != "UNDECIDED":
            return ""
        if self.refused:
            return (f"the other inputs pass, but under {'; '.join(self.refused)} the solver "
                    f"cannot run the test ({'; '.join(dict.fromkeys(self.refused.values()))}); "
                    f"it turns on {', '.join(self.questions)}; the cheapest test that settles "
                    f"it: {self.test}")
        open_ = [METRICS[m.metric].split(" (")[0] for m in self.metrics
                 if m.status == "UNDECIDED"]
        return (f"the model's and the prototype's central bands straddle the "
                f"{self.tolerance:.0%} tolerance on "
                f"{len(open_)} of {len(self.metrics)} quantities ({', '.join(open_)}); it "
                f"turns on {'; '.join(self.deciding)} ({', '.join(self.questions)}); the "
                f"cheapest test that settles it: {self.test}"
                + (f" (then: {'; '.join(self.tests[1:])})" if len(self.tests) > 1 else ""))

    def to_record(self) -> dict[str, Any]:
        return {"verdict": self.verdict, "tolerance": self.tolerance,
                "deciding_variants": self.deciding, "deciding_questions": self.questions,
                "cheapest_test": self.test, "tests": self.tests,
                "assumptions": self.assumptions, "refused_variants": self.refused,
                "metrics": [{"metric": m.metric, "status": m.status,
                             "worst_mismatch": m.worst, "best_mismatch": m.best,
                             "deciding_variants": m.deciding} for m in self.metrics]}


def _worst(x: np.ndarray) -> float:
    return float(np.nanmax(x)) if np.any(~np.isnan(x)) else 0.0


def decide(proto: dict[str, np.ndarray], model: Band, prototype: Band | None = None, *,
           tolerance: float = TOLERANCE) -> Decision:
    """The verdict of the `model` band against the prototype's curves `proto` (METRICS key
    -> (k,), at the band's levels) and its band `prototype` (None: the curves alone)."""
    model, prototype, assumptions = paired_slack(model, prototype)
    mlo, mhi = model.central()
    plo, phi = prototype.central() if prototype is not None else (proto, proto)
    out: list[MetricDecision] = []
    effects: dict[str, float] = {}
    for key in METRICS:
        p, m = np.asarray(proto[key], float), model.nominal[key]
        peak = float(np.nanmax(np.abs(p))) if np.any(~np.isnan(p)) else 0.0
        if peak == 0.0:
            continue
        worst = _worst(np.maximum(mhi[key] - plo[key], phi[key] - mlo[key])) / peak
        best = _worst(np.maximum.reduce([np.zeros_like(p), mlo[key] - phi[key],
                                         plo[key] - mhi[key]])) / peak
        status = "FAIL" if best > tolerance else "PASS" if worst <= tolerance else "UNDECIDED"
        deciding: list[str] = []
        if status == "UNDECIDED":
            deciding = _deciding(key, p, m, peak, model, prototype, tolerance, effects)
        out.append(MetricDecision(key, status, worst, best, deciding))
    kinds = {m.status for m in out}
    verdict = "FAIL" if "FAIL" in kinds else "UNDECIDED" if "UNDECIDED" in kinds else "PASS"
    labels = sorted({x for m in out for x in m.deciding}, key=lambda x: -effects.get(x, 0.0))
    refused = {k: r for k, r in model.refused.items()
               if model.info[k].weight > 0 and not model.info[k].excluded}
    if verdict == "PASS" and refused:  # no curves under these inputs: the test cannot run
        verdict, labels = "UNDECIDED", list(refused)
    else:
        refused = {}
    if verdict != "UNDECIDED":
        labels = []
    info = {**model.info, **(prototype.info if prototype is not None else {})}
    questions = list(dict.fromkeys(info[x].question or x for x in labels))
    return Decision(verdict, out, labels, questions, settling_tests(questions), tolerance,
                    assumptions, refused)


SLACK = ("initial slack", "prototype initial slack")  # the variants' questions, model's first
PAIRED = ("the two nets' initial slack is one input: the model hung with the prototype's "
          "relative slack (geometric similitude), so the model's slack variant is compared "
          "with the prototype's (0 to 1 % on both)")


def paired_slack(model: Band, prototype: Band | None
                 ) -> tuple[Band, Band | None, list[str]]:
    """`model` and `prototype` with their initial slack as one input: the model's slack
    variant moved by the prototype's slack effect (compared with the prototype's nominal, it
    is the slack model against the slack prototype: effects add, as the central interval
    takes them) and the prototype's slack variant carrying no weight; unchanged (and no
    assumption stated) when either band has no weighted slack variant."""
    if prototype is None:
        return model, prototype, []
    ours = [k for k in model.weighted() if model.info[k].question == SLACK[0]]
    theirs = [k for k in prototype.weighted() if prototype.info[k].question == SLACK[1]]
    if len(ours) != 1 or len(theirs) != 1:
        return model, prototype, []
    m, p = ours[0], theirs[0]
    joint = {key: model.variants[m][key] - (prototype.variants[p][key]
                                            - prototype.nominal[key]) for key in METRICS}
    info = dataclasses.replace(model.info[m], question="initial slack (both nets)")
    model = dataclasses.replace(model, variants={**model.variants, m: joint},
                                info={**model.info, m: info})
    prototype = dataclasses.replace(prototype, info={
        **prototype.info, p: dataclasses.replace(prototype.info[p], excluded=PAIRED)})
    return model, prototype, [PAIRED]


def _deciding(key: str, p: np.ndarray, m: np.ndarray, peak: float, model: Band,
              prototype: Band | None, tolerance: float, effects: dict[str, float]
              ) -> list[str]:
    """The weighted variants whose move alone turns quantity `key`'s nominal mismatch across
    the tolerance (each variant's move recorded in `effects`, fraction of the peak); none
    crossing alone: the one that moves the reading most."""
    nominal_ok = _worst(np.abs(m - p)) / peak <= tolerance
    moves = {}
    for label in model.weighted():
        v = model.variants[label][key]
        moves[label] = (_worst(np.abs(v - m)) / peak, _worst(np.abs(v - p)) / peak)
    if prototype is not None:
        for label in prototype.weighted():
            v = prototype.variants[label][key]
            moves[label] = (_worst(np.abs(v - p)) / peak, _worst(np.abs(m - v)) / peak)
    for label, (move, _) in moves.items():
        effects[label] = max(effects.get(label, 0.0), move)
    crossing = [x for x, (_, off) in moves.items() if (off <= tolerance) != nominal_ok]
    if crossing or not moves:
        return sorted(crossing, key=lambda x: -moves[x][0])
    return [max(moves, key=lambda x: moves[x][0])]


def excluded_by_data(band: Band, m: Measurement, *, tolerance: float = TOLERANCE
                     ) -> dict[str, str]:
    """label -> the numbers by which a variant contradicts the lab's test `m`: its
    prediction (counted from h/h_B = 0, as the sensors read) passes an upper bound of `m` by
    more than `tolerance` of the column's measured peak, or misses a measured value by more
    than that where the nominal is within it (a curve the nominal agrees with). A range whose
    end the data contradicts leaves whole (its one run does not say where in the range the
    contradiction starts)."""
    def at(c: dict[str, np.ndarray], key: str) -> np.ndarray:
        return np.interp(m.levels, band.levels, c[key] - c[key][0])

    out = {}
    for label in band.variants:
        for key in m.values:
            col, unit = m.columns[key], (0.01, " %") if key.startswith("strain") else (1.0, "")
            meas, cap = m.values[key], m.bound(key)
            scale = _worst(np.abs(np.concatenate([meas, cap])))
            if not scale > 0:
                continue
            pred, nom = at(band.variants[label], key), at(band.nominal, key)
            over = np.where(np.isnan(cap), -np.inf, pred - cap)
            off = np.where(np.isnan(meas) | (np.abs(nom - meas) > tolerance * scale), -np.inf,
                           np.abs(pred - meas))
            i = int(np.argmax(np.maximum(over, off)))
            if max(over[i], off[i]) > tolerance * scale:
                k, u = unit
                what = f"< {cap[i] / k:.3g}" if over[i] >= off[i] else f"{meas[i] / k:.3g}"
                out[label] = (f"{col} at h/h_B = {m.levels[i]:g}: {pred[i] / k:.3g}{u} "
                              f"predicted, {what}{u} measured (more than {tolerance:.0%} of "
                              f"the column's peak, {scale / k:.3g}{u}, off)")
                break
    return out
