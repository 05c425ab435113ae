"""The central interval of a band: the one-at-a-time variants combined as independent
contributions, each question's answers weighted as its variants state
(`printgen.verification.variants`), and the 10 % and 90 % quantiles of the result.

Definition (stated in the report): at each load level, a variant's effect is its change from
the nominal curve, as a ratio (log) where the nominal and every weighted variant are positive
and the nominal reaches `RATIO_FLOOR` of its peak (deformations that scale, so that two effects
that each halve the reading give a quarter, never a negative reading), else as a difference
(near zero a ratio means nothing: two variants that each read 100 times a vanishing nominal
would combine to 10 000 times it). The answers of one question are exclusive
(one of them is the truth: its weight, the nominal the rest); a range is uniform between the
nominal and its end (`RANGE_POINTS` equal parts). Questions are independent and their effects
add (first order: the combinations are not run). The central interval is [q10, q90] of that
distribution, widened to hold the nominal; the envelope (min/max over every run curve) is kept
apart. A variant with a reason to be excluded carries no weight (it shows in the envelope only).
With one variant per question, 10-90 % drops an answer only when its weight is below 10 % or
when other questions pull the other way; with ~10 questions the sum's tails, not single
variants, set the edges.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

QUANTILES = (0.1, 0.9)  # the central interval: 10 % to 90 % of the weighted combinations
RANGE_POINTS = 5  # a range's uniform spread, taken at the midpoints of 5 equal parts
RATIO_FLOOR = 0.1  # effects combine as ratios where the nominal is >= 10 % of its peak
POINTS_MAX = 4096  # combinations kept per level (more are merged into equal-weight bins)


@dataclass(frozen=True)
class Contribution:
    """One weighted variant's curve (k,) with its question, weight and spread ("answer": the
    probability of this answer; "range": uniform from the nominal to this curve)."""

    question: str
    curve: np.ndarray
    weight: float
    spread: str = "answer"


def quantile(values: np.ndarray, weights: np.ndarray, q: float) -> float:
    """The smallest value whose cumulative weight reaches q (the inverse of the weighted
    distribution function; exact for discrete distributions)."""
    order = np.argsort(values, kind="stable")
    cdf = np.cumsum(weights[order]) / weights.sum()
    i = int(np.searchsorted(cdf, q - 1e-12))
    return float(values[order][min(i, len(order) - 1)])


def _answers(deltas: list[tuple[float, float, str]]) -> tuple[np.ndarray, np.ndarray]:
    """(values, weights) of one question's effect: each answer's delta with its weight, a
    range uniform from 0 to its delta, the nominal (0) the remaining weight."""
    vals, wts = [], []
    for delta, w, spread in deltas:
        if spread == "range":
            vals += [delta * (j + 0.5) / RANGE_POINTS for j in range(RANGE_POINTS)]
            wts += [w / RANGE_POINTS] * RANGE_POINTS
        else:
            vals.append(delta)
            wts.append(w)
    rest = 1.0 - sum(wts)
    if rest < -1e-9:
        raise ValueError(f"the weights of one question add to {1 - rest:.3g} > 1")
    if rest > 1e-12:
        vals.append(0.0)
        wts.append(rest)
    return np.array(vals), np.array(wts)


def _combine(parts: list[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    """The distribution of the sum of independent discrete contributions."""
    v, w = np.zeros(1), np.ones(1)
    for pv, pw in parts:
        v = (v[:, None] + pv[None, :]).ravel()
        w = (w[:, None] * pw[None, :]).ravel()
        if v.size > POINTS_MAX:
            v, w = _merged(v, w)
    return v, w


def _merged(v: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """POINTS_MAX equal-weight bins of the sorted distribution, each at its weighted mean."""
    order = np.argsort(v, kind="stable")
    v, w = v[order], w[order]
    edge = np.cumsum(w) / w.sum()
    which = np.minimum((edge * POINTS_MAX - 1e-9).astype(int), POINTS_MAX - 1)
    wb = np.bincount(which, weights=w, minlength=POINTS_MAX)
    vb = np.bincount(which, weights=v * w, minlength=POINTS_MAX)
    keep = wb > 0
    return vb[keep] / wb[keep], wb[keep]


def central_interval(nominal: np.ndarray, parts: list[Contribution],
                     quantiles: tuple[float, float] = QUANTILES
                     ) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi), each (k,), of the combined contributions at every level (see the module's
    definition); NaN where the nominal is NaN; a variant NaN at a level leaves that level's
    combination (its weight goes to the nominal there)."""
    nominal = np.asarray(nominal, float)
    lo, hi = np.full(nominal.shape, np.nan), np.full(nominal.shape, np.nan)
    peak = float(np.nanmax(np.abs(nominal))) if np.any(~np.isnan(nominal)) else 0.0
    for i, n in enumerate(nominal):
        if np.isnan(n):
            continue
        here = [(float(c.curve[i]), c) for c in parts if c.weight > 0 and
                not np.isnan(c.curve[i])]
        ratio = n >= RATIO_FLOOR * peak and n > 0 and all(x > 0 for x, _ in here)
        by_q: dict[str, list[tuple[float, float, str]]] = {}
        for x, c in here:
            delta = np.log(x / n) if ratio else x - n
            by_q.setdefault(c.question, []).append((delta, c.weight, c.spread))
        v, w = _combine([_answers(d) for d in by_q.values()])
        a, b = (quantile(v, w, q) for q in quantiles)
        if ratio:
            a, b = n * np.exp(a), n * np.exp(b)
        else:
            a, b = n + a, n + b
        lo[i], hi[i] = min(a, n), max(b, n)
    return lo, hi
