"""A bounded fit of several parameters of the printed net to a measured loading test, that
explains the measurement or says it cannot.

Parameters, each bounded by what a lab would see or measure (`BOUNDS`):
- net_factor: multiplier on the printed net's force law (strands and printed border frame);
- net_slack: initial slack of the net's strands (a zero-force strain before they pull);
- cable_slack: initial slack of the border cables (the same, on the cables);
and, as discrete choices tried in turn, the flume mounting and the panel-test orientation
(`printgen.scene.scenes`), the net's span (printed width or the flume's free section,
`printgen.scene.mount`) and its bottom row free or held on the bed
(`printgen.scene.forms`). Slack is a law with a first, (nearly) flat segment (`slackened`):
the same to first order as a rest length (1 + slack) times longer.

For every discrete choice the continuous parameters are searched (scipy's bounded
least_squares, trust-region reflective, on the parameters scaled to [0, 1]) for the least
mismatch (`measured.objective`, as a sum of squared weighted residuals: `residuals`): a
short screen of every choice, then a full search of the SCREEN_KEEP best. The
best choice is reported with the mismatch before (the nominal model) and after, and with
what the data determine: the singular values of the scaled residuals' Jacobian at the best
point and each parameter's sensitivity. The fit "explains" the test when every measured
column's RMS mismatch is below `EXPLAINS` of its measured peak; otherwise it says so and no
profile may be written from it. Only the printed model is fitted; the prototype stays a
prediction.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from dataclasses import dataclass

import numpy as np

from printgen.scaling.record import Design
from printgen.scene.forms import BEDS, slack_laws
from printgen.scene.options import SceneOptions, build_scene
from printgen.scene.scenes import MOUNTINGS, ORIENTATIONS, BarrierScene
from printgen.verification.bands import curves
from printgen.verification.measured import Measurement, mismatch, objective
from printgen.verification.preprint import sweep

# (low, high, nominal) of each continuous parameter
BOUNDS = {
    "net_factor": (0.25, 4.0, 1.0),  # printed flexible nets: modulus set by print conditions
    "net_slack": (0.0, 0.03, 0.0),  # 3 % slack sags visibly: a lab would see it
    "cable_slack": (0.0, 0.03, 0.0),  # a 3 % slack cable sags 10 % of its span at rest
}
Choice = tuple[str, "str | None", "float | None", str]  # mounting, orientation, span, bed
EXPLAINS = 0.15  # explained: RMS mismatch below 15 % of the measured peak on every column
MAX_EVALUATIONS = 15  # least-squares steps for a retained choice (each: 1 + free sweeps)
SCREEN_EVALUATIONS = 3  # ... for every discrete choice first (a screen)
SCREEN_KEEP = 2  # choices searched on after the screen
XTOL = 1e-4  # stop once a step moves the scaled parameters by less than this (relative)
STEP = 0.01  # finite-difference step of the Jacobians, fraction of each range
DETERMINED = 0.1  # a singular value above 10 % of the largest: that direction is determined
AT_BOUND = 0.01  # a parameter within 1 % of its range from a bound (not its nominal) is at it


@dataclass(frozen=True)
class Params:
    """One parameter set of the printed model (see the module docstring)."""

    net_factor: float = 1.0
    net_slack: float = 0.0
    cable_slack: float = 0.0
    mounting: str = MOUNTINGS[0]
    orientation: str | None = None  # None: the orientation the material profile records
    span: float | None = None  # lateral supports this far apart (m; None: the printed width)
    bed: str = BEDS[0]  # the net's bottom row free or held on the bed

    def scaled(self) -> np.ndarray:
        """The continuous parameters on [0, 1] (net_factor on a log scale)."""
        return np.array([_to_unit(k, getattr(self, k)) for k in BOUNDS])

    def with_scaled(self, x: np.ndarray) -> Params:
        return dataclasses.replace(self, **{k: _from_unit(k, float(v))
                                            for k, v in zip(BOUNDS, x, strict=True)})


def _to_unit(key: str, v: float) -> float:
    lo, hi, _ = BOUNDS[key]
    if key == "net_factor":
        return (math.log(v) - math.log(lo)) / (math.log(hi) - math.log(lo))
    return (v - lo) / (hi - lo)


def _from_unit(key: str, u: float) -> float:
    lo, hi, _ = BOUNDS[key]
    u = min(max(u, 0.0), 1.0)
    if key == "net_factor":
        return math.exp(math.log(lo) + u * (math.log(hi) - math.log(lo)))
    return lo + u * (hi - lo)


def fit_scene(d: Design, p: Params, coarsen: int = 1) -> BarrierScene:
    """The printed model's scene with parameter set `p` (on the design's mesh x coarsen)."""
    o = SceneOptions(mounting=p.mounting, orientation=p.orientation, bed=p.bed, span=p.span,
                     net_factor=p.net_factor, frame_factor=p.net_factor, coarsen=coarsen)
    return slack_laws(build_scene(d, o), p.net_slack, p.cable_slack)


def predict(d: Design, p: Params, m: Measurement, lv: np.ndarray, coarsen: int = 1,
            load_kw: dict | None = None) -> dict[str, np.ndarray]:
    """The model's curves with `p`, counted from h / h_B = 0, at the measured levels; NaN
    where a level did not converge."""
    c = curves(sweep(fit_scene(d, p, coarsen), lv, **(load_kw or {})))
    return {k: np.interp(m.levels, lv, c[k] - c[k][0]) for k in m.values}


def residuals(m: Measurement, pred: dict[str, np.ndarray]) -> np.ndarray:
    """Every measured point's mismatch over its column's peak (a bound: its excess only),
    weighted so that their sum of squares is `measured.objective` (columns weigh alike)."""
    out = []
    for key in m.values:
        meas, cap, y = m.values[key], m.bound(key), pred[key]
        ok, capped = ~np.isnan(meas), ~np.isnan(cap)
        peak = float(np.abs(meas[ok]).max()) if ok.any() else float(np.abs(cap[capped]).max())
        r = np.concatenate([meas[ok] - y[ok], np.maximum(y[capped] - cap[capped], 0)]) / peak
        out.append(r / math.sqrt(len(r) * len(m.values)))
    return np.nan_to_num(np.concatenate(out), nan=1.0)  # an unconverged level: a full miss


@dataclass(frozen=True)
class Identifiability:
    """What the data determine at the best point: singular values of the scaled residuals'
    Jacobian (largest first), the parameter combination of each (rows: BOUNDS order), and
    each parameter's sensitivity (norm of its Jacobian column, per unit of its range)."""

    singular_values: np.ndarray
    directions: np.ndarray
    sensitivity: dict[str, float]

    def determined(self) -> list[str]:
        """Parameters whose own direction is determined (DETERMINED of the largest value)."""
        s = self.singular_values
        if not s.size or s[0] <= 0:
            return []
        strong = self.directions[:, s > DETERMINED * s[0]]
        return [k for i, k in enumerate(BOUNDS) if np.abs(strong[i]).max(initial=0) > 0.5]


@dataclass(frozen=True)
class MultiFit:
    """The best parameter set, mismatches before (nominal) and after, per discrete choice the
    best objective, identifiability, and whether the fit explains the test."""

    params: Params
    before: list
    after: list
    predicted: dict[str, np.ndarray]
    choices: dict[Choice, tuple[Params, float]]
    identifiability: Identifiability
    evaluations: int
    explains: bool
    at_bounds: tuple[str, ...] = ()  # parameters the best set pushes against a bound

    kind = "multi"
    at_bound = False  # the one-factor fit's flag; a multi fit says `explains` instead

    @property
    def label(self) -> str:
        p = self.params
        return (f"fitted: net x {p.net_factor:.3g}, slack {p.net_slack:.1%} / "
                f"{p.cable_slack:.1%}")

    def to_record(self) -> dict:
        """The fit in report.json: parameters, bounds, choices, identifiability, mismatches."""
        ident = self.identifiability
        return {"kind": self.kind, "explains": self.explains, "sentence": self.sentence(),
                "params": dataclasses.asdict(self.params), "at_bounds": list(self.at_bounds),
                "bounds": {k: {"low": lo, "high": hi, "nominal": nom}
                           for k, (lo, hi, nom) in BOUNDS.items()},
                "choices": [{"mounting": k[0], "orientation": k[1], "span_m": k[2],
                             "bed": k[3], "params": dataclasses.asdict(p), "objective": o}
                            for k, (p, o) in self.choices.items()],
                "identifiability": {"singular_values": ident.singular_values,
                                    "directions": ident.directions,
                                    "sensitivity": ident.sensitivity,
                                    "determined": ident.determined()},
                "mismatch_nominal": self.before, "mismatch_fitted": self.after,
                "predicted": self.predicted, "evaluations": self.evaluations}

    def sentence(self) -> str:
        p = self.params
        worst = max(mm.rms_rel for mm in self.after)
        what = (f"net law x {p.net_factor:.3g}, net slack {p.net_slack:.2%}, cable slack "
                f"{p.cable_slack:.2%}, mounting {p.mounting}, orientation "
                f"{p.orientation or 'as profiled'}, span "
                f"{'printed width' if p.span is None else f'{p.span * 1e3:g} mm'}, bottom row "
                f"{p.bed}")
        if self.at_bounds and worst < EXPLAINS:
            edge = ", ".join(self.at_bounds)
            return (f"NOT explained: the best set, {what}, leaves {worst:.0%} of the measured "
                    f"peak, but only with {edge} at the end of its range (an "
                    "explanation needs parameters inside their bounds); no profile is written")
        if self.explains:
            return (f"explained within the bounds by {what} (worst RMS mismatch {worst:.0%} of "
                    "the measured peak); determined: "
                    f"{', '.join(self.identifiability.determined()) or 'none'}")
        return (f"NOT explained: no parameter set within the bounds brings every column within "
                f"{EXPLAINS:.0%} of its measured peak; the best, {what}, leaves {worst:.0%}; no "
                "profile is written")


PATH_STEP = 0.1  # load path of each fit evaluation: this step, plus the measured levels


def fit_levels(m: Measurement) -> np.ndarray:
    """The load path a fit sweeps: 0 to the highest measured level by PATH_STEP, and every
    measured level."""
    top = float(m.levels.max())
    return np.union1d(np.round(np.arange(0.0, top + 1e-9, PATH_STEP), 10), m.levels)


def fit_measured(d: Design, m: Measurement, lv: np.ndarray, *, coarsen: int = 1,
                 load_kw: dict | None = None,
                 choices: list[tuple] | None = None,
                 free: tuple[str, ...] = tuple(BOUNDS),
                 free_section: float | None = None) -> MultiFit:
    """The bounded fit of the module docstring over every (mounting, orientation, span, bed)
    choice (or `choices`, bed "free" when left out; span None or `free_section` when given),
    searching the continuous
    parameters `free` (the others stay nominal); `lv` : the load path swept for each
    evaluation (0 first, up to the highest measured)."""
    from scipy.optimize import least_squares

    lv = np.asarray(lv, float)
    cache: dict[Params, dict[str, np.ndarray]] = {}

    def run(p: Params) -> dict[str, np.ndarray]:
        if p not in cache:
            cache[p] = predict(d, p, m, lv, coarsen, load_kw)
        return cache[p]

    if choices is None:
        spans = [None] + ([free_section] if free_section is not None else [])
        choices = list(itertools.product(MOUNTINGS, ORIENTATIONS, spans, BEDS))
    choices = [(*c, BEDS[0]) if len(c) == 3 else tuple(c) for c in choices]
    idx = [list(BOUNDS).index(k) for k in free]
    nominal = run(Params())

    def search(base: Params, evaluations: int) -> tuple[Params, float]:
        def full(y: np.ndarray) -> np.ndarray:
            x = base.scaled()
            x[idx] = y
            return x

        def res_of(y: np.ndarray) -> np.ndarray:
            return residuals(m, run(base.with_scaled(full(y))))

        res = least_squares(res_of, base.scaled()[idx], bounds=(0.0, 1.0), diff_step=STEP,
                            max_nfev=evaluations, xtol=XTOL)
        fitted = base.with_scaled(full(res.x))
        return fitted, objective(m, run(fitted))

    screen = len(choices) > SCREEN_KEEP
    best = {c: search(Params(mounting=c[0], orientation=c[1], span=c[2], bed=c[3]),
                      SCREEN_EVALUATIONS if screen else MAX_EVALUATIONS) for c in choices}
    if screen:  # the most promising choices, searched on from their screened point
        for c in sorted(best, key=lambda k: best[k][1])[:SCREEN_KEEP]:
            best[c] = search(best[c][0], MAX_EVALUATIONS)
    params = min(best.values(), key=lambda pv: pv[1])[0]
    pred = run(params)
    after = mismatch(m, pred)
    ident = _identifiability(m, params, pred, run)
    edge = at_bounds(params)
    ok = all(mm.rms_rel < EXPLAINS for mm in after if not math.isnan(mm.rms_rel)) and not edge
    return MultiFit(params, mismatch(m, nominal), after, pred, best, ident, len(cache), ok,
                    edge)


def at_bounds(p: Params) -> tuple[str, ...]:
    """The continuous parameters of `p` within AT_BOUND of a bound other than their nominal
    (a fit pushed there wants more than physics allows)."""
    out = []
    for k, (_lo, _hi, nom) in BOUNDS.items():
        u, n = _to_unit(k, getattr(p, k)), _to_unit(k, nom)
        if (u < AT_BOUND and n >= AT_BOUND) or (u > 1 - AT_BOUND and n <= 1 - AT_BOUND):
            out.append(k)
    return tuple(out)


def _identifiability(m: Measurement, p: Params, pred: dict[str, np.ndarray], run
                     ) -> Identifiability:
    """Forward differences of the scaled residuals at `p` (backward at an upper bound)."""
    r0, x0 = residuals(m, pred), p.scaled()
    cols, sens = [], {}
    for i, key in enumerate(BOUNDS):
        h = STEP if x0[i] + STEP <= 1.0 else -STEP
        x = x0.copy()
        x[i] += h
        col = (residuals(m, run(p.with_scaled(x))) - r0) / h
        cols.append(col)
        sens[key] = float(np.linalg.norm(col))
    _, s, vt = np.linalg.svd(np.column_stack(cols), full_matrices=False)
    return Identifiability(s, vt.T, sens)
