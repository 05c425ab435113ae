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

The mismatch (`measured.objective`, as a sum of squared weighted residuals: `residuals`)
scores a measured value's miss over its column's peak and a bound's excess over the bound
(`measured.SCORING`). Every sweep solves h / h_B = 0 and the measured levels only
(`measured.measured_path`). The search runs coarse to fine, every batch of trials on the
workers at once (`printgen.executor.local`):
1. screen: every discrete choice starts from the nominal parameters, on the band's first
   coarse net (`bands.COARSENINGS`, strands as much stiffer: the same membrane stiffness),
   and takes SCREEN_STEPS Gauss-Newton steps (each: the point and a forward difference per
   free parameter, all choices in one batch), then its stepped point;
2. search: the SCREEN_KEEP best choices, each from its screened point, on the design's own
   net (scipy's bounded least_squares, trust-region reflective, on the parameters scaled to
   [0, 1]), one worker each;
3. the best point's identifiability (the singular values of the scaled residuals' Jacobian
   there, each parameter's sensitivity) and its profiles: the mismatch along each free
   parameter over its range (PROFILE_POINTS values, the others held at the best), which says
   which parameters the data determine and which are flat.
The sweeps this runs, at most, are `planned_sweeps` (the run's estimate counts them).

The fit "explains" the test when every measured column's scored RMS mismatch is below
`EXPLAINS`, it improves every measured column on the nominal (`measured.not_improved`) and
every parameter is inside its bounds; otherwise it says so and no profile may be written from
it. A slack that leaves its part without load (`IDLE`), at its bound or below, is said as that:
the part carries nothing in the fit. Only the printed model is fitted; the prototype stays a
prediction.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import time
from dataclasses import dataclass, field

import numpy as np

from printgen.executor.local import collect, shared_pool, submit_jobs
from printgen.scaling.record import Design
from printgen.scene.forms import BEDS, slack_laws
from printgen.scene.options import SceneOptions, build_scene
from printgen.scene.scenes import MOUNTINGS, ORIENTATIONS, BarrierScene
from printgen.verification.bands import COARSENINGS, curves, meshable
from printgen.verification.measured import (
    Measurement,
    measured_path,
    mismatch,
    not_improved,
    objective,
    scored,
)
from printgen.verification.preprint import sweep

# (low, high, nominal) of each continuous parameter
BOUNDS = {
    "net_factor": (0.25, 4.0, 1.0),  # printed flexible nets: modulus set by print conditions
    "net_slack": (0.0, 0.03, 0.0),  # 3 % slack sags visibly: a lab would see it
    "cable_slack": (0.0, 0.03, 0.0),  # a 3 % slack cable sags 10 % of its span at rest
}
# A slack may only mean that its part never pulls (at its upper bound, or anywhere above the
# stretch the part sees): then the fit says so, not a value (checked on the fitted sweep: the
# part's largest tension below IDLE_SHARE of the nominal's)
IDLE = {"cable_slack": "the border cables carry no load in the fit"}
IDLE_SHARE = 0.01  # a part pulling less than 1 % of its nominal tension carries nothing
Choice = tuple[str, "str | None", "float | None", str]  # mounting, orientation, span, bed
EXPLAINS = 0.15  # explained: scored RMS mismatch below 15 % on every column (`measured.scored`)
# The search's size: its sweeps and time on the bundled paper test are recorded in
# benchmarks/measurements.md#fit-paper-test
MAX_EVALUATIONS = 15  # least-squares steps for a retained choice (each: 1 + free sweeps)
SCREEN_STEPS = 2  # Gauss-Newton steps of every discrete choice on the coarse net first
SCREEN_KEEP = 2  # choices searched on after the screen
SCREEN_TRUST = 0.5  # a screening step moves the scaled parameters by at most half their range
XTOL = 1e-4  # stop once a step moves the scaled parameters by less than this (relative)
STEP = 0.01  # finite-difference step of the Jacobians, fraction of each range
DETERMINED = 0.1  # a singular value above 10 % of the largest: that direction is determined
AT_BOUND = 0.01  # a parameter within 1 % of its range from a bound (not its nominal) is at it
PROFILE_POINTS = 5  # values of each parameter's profile, evenly over its (scaled) range
# a parameter is determined by the data when, over its range (the others held), the scored
# RMS mismatch rises by more than this above the best: a third of EXPLAINS, a change the
# explanation's own criterion would notice; flat (not determined) otherwise
PROFILE_RISE = EXPLAINS / 3


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

    @property
    def choice(self) -> Choice:
        return (self.mounting, self.orientation, self.span, self.bed)


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


@dataclass(frozen=True)
class Trial:
    """One sweep of the fit: the curves at the measured levels (from h / h_B = 0), NaN where
    a level did not converge, and the border cables' largest tension over the path (N)."""

    curves: dict[str, np.ndarray]
    cable_n: float
    cpu_s: float = 0.0  # the trial's CPU in its process (scene and sweep)


def trial(d: Design, p: Params, m: Measurement, lv: np.ndarray, coarsen: int = 1,
          load_kw: dict | None = None) -> Trial:
    """The model swept with `p` over `lv` (a worker job: module-level, picklable)."""
    cpu = time.process_time()
    run = sweep(fit_scene(d, p, coarsen), lv, **(load_kw or {}))
    c = curves(run)
    cable = run.deformation.max_cable_tension
    return Trial({k: np.interp(m.levels, lv, c[k] - c[k][0]) for k in m.values},
                 float(np.nanmax(cable)) if cable.size else 0.0,
                 time.process_time() - cpu)


def predict(d: Design, p: Params, m: Measurement, lv: np.ndarray, coarsen: int = 1,
            load_kw: dict | None = None) -> dict[str, np.ndarray]:
    """The model's curves with `p`, counted from h / h_B = 0, at the measured levels; NaN
    where a level did not converge."""
    return trial(d, p, m, lv, coarsen, load_kw).curves


def residuals(m: Measurement, pred: dict[str, np.ndarray]) -> np.ndarray:
    """Every measured point's scored miss (`measured.scored`), weighted so that their sum of
    squares is `measured.objective` (columns weigh alike)."""
    out = []
    for key in m.values:
        r = scored(m, key, pred[key])[1]
        out.append(r / math.sqrt(len(r) * len(m.values)))
    return np.nan_to_num(np.concatenate(out), nan=1.0)  # an unconverged level: a full miss


class Trials:
    """The fit's sweeps, each run once (cached by parameters and net) and counted by net;
    `many` runs a batch on the workers at once."""

    def __init__(self, d: Design, m: Measurement, lv: np.ndarray, load_kw: dict | None):
        self.d, self.m, self.lv, self.load_kw = d, m, lv, load_kw
        self.cache: dict[tuple[Params, int], Trial] = {}
        self.count: dict[int, int] = {}
        self.cpu_s = 0.0  # the sweeps' CPU, summed over the processes that ran them

    def many(self, ps: list[Params], coarsen: int = 1) -> list[Trial]:
        todo = list(dict.fromkeys(p for p in ps if (p, coarsen) not in self.cache))
        jobs: list[tuple] = [(trial, (self.d, p, self.m, self.lv, coarsen, self.load_kw), {})
                             for p in todo]
        for p, t in zip(todo, collect(submit_jobs(jobs)), strict=True):
            self.cache[(p, coarsen)] = t
            self.cpu_s += t.cpu_s
        self.count[coarsen] = self.count.get(coarsen, 0) + len(todo)
        return [self.cache[(p, coarsen)] for p in ps]

    def one(self, p: Params, coarsen: int = 1) -> Trial:
        return self.many([p], coarsen)[0]

    def add(self, p: Params, t: Trial, sweeps: int, cpu_s: float, coarsen: int = 1) -> None:
        """A trial run elsewhere (a worker's search), the sweeps that search ran and their
        CPU."""
        self.cache[(p, coarsen)] = t
        self.count[coarsen] = self.count.get(coarsen, 0) + sweeps
        self.cpu_s += cpu_s


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
class Profile:
    """The mismatch along one parameter (the others held at the best): its values, the
    scored RMS mismatch at each (`measured.objective`'s root), whether the data determine it
    (the mismatch rises by more than PROFILE_RISE above the best somewhere in its range) and
    the range of values within PROFILE_RISE of the best (what the data allow)."""

    values: np.ndarray
    rms: np.ndarray
    best: float
    determined: bool
    allowed: tuple[float, float]

    def to_record(self) -> dict:
        return {"values": self.values, "rms_mismatch": self.rms, "best_rms": self.best,
                "determined": self.determined, "allowed": list(self.allowed),
                "held": "the other parameters at the best set"}


@dataclass(frozen=True)
class MultiFit:
    """The best parameter set, mismatches before (nominal) and after, per discrete choice the
    best objective, identifiability and profiles, and whether the fit explains the test."""

    params: Params
    before: list
    after: list
    predicted: dict[str, np.ndarray]
    choices: dict[Choice, tuple[Params, float]]
    identifiability: Identifiability
    evaluations: int
    explains: bool
    at_bounds: tuple[str, ...] = ()  # parameters the best set pushes against a bound
    idle: tuple[str, ...] = ()  # the slacks whose part carries no load in the fit (IDLE)
    profiles: dict[str, Profile] = field(default_factory=dict)
    sweeps: dict[str, int] = field(default_factory=dict)  # "coarse x2", "own net": sweeps run
    cpu_s: float = 0.0  # the sweeps' CPU over every process (bench fit)
    searched: tuple[Choice, ...] = ()  # the choices searched on the design's own net (the
    # others' objective is their screen's, on the coarse net)

    kind = "multi"
    at_bound = False  # the one-factor fit's flag; a multi fit says `explains` instead

    @property
    def unimproved(self) -> list[tuple[str, float, float]]:
        return not_improved(self.before, self.after)

    @property
    def label(self) -> str:
        p = self.params
        return (f"fitted: net x {p.net_factor:.3g}, slack {p.net_slack:.1%} / "
                f"{p.cable_slack:.1%}")

    def net_of(self, c: Choice) -> str:
        """Where choice `c`'s best objective was found: its search or the screen."""
        return "own net" if c in self.searched or not self.searched else "coarse screen"

    def flat(self) -> list[str]:
        """The free parameters the data do not determine (their profile is flat)."""
        return [k for k, pr in self.profiles.items() if not pr.determined]

    def to_record(self) -> dict:
        """The fit in report.json: parameters, bounds, choices, identifiability, profiles,
        mismatches."""
        from printgen.verification.measured import SCORING

        ident = self.identifiability
        return {"kind": self.kind, "explains": self.explains, "sentence": self.sentence(),
                "params": dataclasses.asdict(self.params), "at_bounds": list(self.at_bounds),
                "idle": {k: IDLE[k] for k in self.idle},
                "bounds": {k: {"low": lo, "high": hi, "nominal": nom}
                           for k, (lo, hi, nom) in BOUNDS.items()},
                "choices": [{"mounting": k[0], "orientation": k[1], "span_m": k[2],
                             "bed": k[3], "params": dataclasses.asdict(p), "objective": o,
                             "net": self.net_of(k)}
                            for k, (p, o) in self.choices.items()],
                "identifiability": {"singular_values": ident.singular_values,
                                    "directions": ident.directions,
                                    "sensitivity": ident.sensitivity,
                                    "determined": ident.determined()},
                "profiles": {k: pr.to_record() for k, pr in self.profiles.items()},
                "determined_by_profile": [k for k, pr in self.profiles.items()
                                          if pr.determined],
                "not_determined": self.flat(), "scoring": SCORING,
                "not_improved": [{"column": c, "before": b, "after": a}
                                 for c, b, a in self.unimproved],
                "mismatch_nominal": self.before, "mismatch_fitted": self.after,
                "predicted": self.predicted, "evaluations": self.evaluations,
                "sweeps": self.sweeps}

    def _what(self) -> str:
        p = self.params
        slack = ("border cables carrying no load" if "cable_slack" in self.idle
                 else f"cable slack {p.cable_slack:.2%}")
        return (f"net law x {p.net_factor:.3g}, net slack {p.net_slack:.2%}, {slack}, "
                f"mounting {p.mounting}, orientation {p.orientation or 'as profiled'}, span "
                f"{'printed width' if p.span is None else f'{p.span * 1e3:g} mm'}, bottom row "
                f"{p.bed}")

    def sentence(self) -> str:
        worst = max(mm.rms_rel for mm in self.after)
        what = self._what()
        idle = "".join(f"; {IDLE[k]} (slack {getattr(self.params, k):.2%} or more, more "
                       "than the net ever stretches them: any larger slack fits the same, "
                       "so the data say only that they stay slack)" for k in self.idle)
        flat = self.flat()
        det = (f"; not determined by the data (flat mismatch along): {', '.join(flat)}"
               if flat else "")
        edge = [k for k in self.at_bounds if k not in self.idle]
        worse = "; ".join(f"{c} {b:.0%} -> {a:.0%}" for c, b, a in self.unimproved)
        if self.explains:
            return (f"explained within the bounds by {what} (worst scored RMS mismatch "
                    f"{worst:.0%}); determined: "
                    f"{', '.join(self.identifiability.determined()) or 'none'}{det}")
        if worst < EXPLAINS and (self.at_bounds or worse):
            why = []
            if edge:
                why.append(f"only with {', '.join(edge)} at the end of its range (an "
                           "explanation needs parameters inside their bounds)")
            if any(k in self.idle for k in self.at_bounds):
                why.append("only with a part that carries no load, its slack at the end of "
                           "its range")
            if worse:
                why.append(f"it does not improve every measured column (scored RMS, nominal "
                           f"-> fitted: {worse})")
            return (f"NOT explained: the best set, {what}, leaves {worst:.0%}{idle}, but "
                    f"{'; and '.join(why)}; no profile is written{det}")
        return (f"NOT explained: no parameter set within the bounds brings every column within "
                f"{EXPLAINS:.0%} (scored RMS mismatch); the best, {what}, leaves "
                f"{worst:.0%}{idle}; no profile is written{det}")



def fit_levels(m: Measurement) -> np.ndarray:
    """The load path a fit sweeps: h / h_B = 0 and every measured level
    (`measured.measured_path`)."""
    return measured_path(m)


def all_choices(free_section: float | None = None) -> list[Choice]:
    """Every discrete choice (mounting, orientation, span, bed): the span the printed width,
    or also the flume's free section when given."""
    spans = [None] + ([free_section] if free_section is not None else [])
    return list(itertools.product(MOUNTINGS, ORIENTATIONS, spans, BEDS))


def planned_sweeps(choices: int, free: int = len(BOUNDS)) -> dict[str, int]:
    """The sweeps `fit_measured` runs at most over `choices` discrete choices with `free`
    continuous parameters: "coarse" on the screen's coarse net, "fine" on the design's own
    net (when the screen is skipped, every sweep is fine)."""
    search = MAX_EVALUATIONS * (1 + free)  # least_squares: each step a point and a Jacobian
    final = 1 + free + free * PROFILE_POINTS  # the nominal, the Jacobian, the profiles
    if choices <= SCREEN_KEEP:
        return {"coarse": 0, "fine": choices * search + final}
    return {"coarse": choices * (SCREEN_STEPS * (1 + free) + 1),
            "fine": SCREEN_KEEP * search + final}


def screen_coarsen(d: Design) -> int:
    """The screen's net: the band's first coarse net when the design's mesh allows it."""
    return COARSENINGS[0] if meshable(d, COARSENINGS[0]) else 1


def fit_measured(d: Design, m: Measurement, lv: np.ndarray, *, coarsen: int = 1,
                 load_kw: dict | None = None,
                 choices: list[tuple] | None = None,
                 free: tuple[str, ...] = tuple(BOUNDS),
                 free_section: float | None = None) -> MultiFit:
    """The bounded fit of the module docstring over every (mounting, orientation, span, bed)
    choice (or `choices`, bed "free" when left out; span None or `free_section` when given),
    searching the continuous parameters `free` (the others stay nominal); `lv` : the load
    path swept for each evaluation (0 first, up to the highest measured; `fit_levels`).
    `coarsen`: the design's net made coarser for every sweep (tests)."""
    with shared_pool():
        return _fit(d, m, np.asarray(lv, float), coarsen, load_kw, choices, free,
                    free_section)


def _fit(d: Design, m: Measurement, lv: np.ndarray, coarsen: int, load_kw: dict | None,
         choices: list[tuple] | None, free: tuple[str, ...], free_section: float | None
         ) -> MultiFit:
    runs = Trials(d, m, lv, load_kw)
    if choices is None:
        choices = all_choices(free_section)
    picked = [(*c, BEDS[0]) if len(c) == 3 else tuple(c) for c in choices]
    idx = [list(BOUNDS).index(k) for k in free]
    nominal = runs.one(Params(), coarsen)
    bases = [Params(mounting=c[0], orientation=c[1], span=c[2], bed=c[3]) for c in picked]
    best: dict[Choice, tuple[Params, float]] = {}
    if len(bases) > SCREEN_KEEP:  # 1. the screen, every choice at once on the coarse net
        best = _screen(runs, bases, idx, coarsen * screen_coarsen(d))
        keep = sorted(best, key=lambda c: best[c][1])[:SCREEN_KEEP]
        starts = [best[c][0] for c in keep]
    else:
        starts = bases
    # 2. the search on the design's own net, one choice per worker
    jobs: list[tuple] = [(search_job, (d, m, lv, load_kw, s, tuple(idx), coarsen), {})
                         for s in starts]
    for p, obj, t, n, cpu in collect(submit_jobs(jobs)):
        runs.add(p, t, n, cpu, coarsen)
        best[p.choice] = (p, obj)
    params = min((best[s.choice] for s in starts), key=lambda pv: pv[1])[0]
    fitted = runs.one(params, coarsen)
    pred = fitted.curves
    before, after = mismatch(m, nominal.curves), mismatch(m, pred)
    # 3. what the data determine: the Jacobian and the profiles, in one batch
    ident, profiles = _determination(runs, params, idx, coarsen)
    edge = at_bounds(params)
    idle = tuple(k for k in IDLE if k in free and _idle(fitted, nominal))
    ok = explained(before, after, params)
    sweeps = {("own net" if k == coarsen else f"coarse x{k // coarsen}"): n
              for k, n in sorted(runs.count.items())}
    return MultiFit(params, before, after, pred, best, ident, sum(runs.count.values()), ok,
                    edge, idle, profiles, sweeps, runs.cpu_s, tuple(s.choice for s in starts))


def explained(before: list, after: list, params: Params) -> bool:
    """The module docstring's rule: every column's scored RMS mismatch below EXPLAINS, every
    measured column improved on the nominal (`measured.not_improved`), and every parameter
    inside its bounds (`at_bounds`). Only then may a profile be written from the fit."""
    close = all(mm.rms_rel < EXPLAINS for mm in after if not math.isnan(mm.rms_rel))
    return close and not not_improved(before, after) and not at_bounds(params)


def _screen(runs: Trials, bases: list[Params], idx: list[int], k: int
            ) -> dict[Choice, tuple[Params, float]]:
    """SCREEN_STEPS Gauss-Newton steps of every choice from the nominal parameters (bounded
    to [0, 1], each step at most SCREEN_TRUST), all choices' sweeps in one batch per step;
    the best point each choice reached and its objective."""
    m, n = runs.m, len(idx)
    xs = [b.scaled() for b in bases]
    best: dict[Choice, tuple[Params, float]] = {}
    for step in range(SCREEN_STEPS + 1):
        points = [b.with_scaled(x) for b, x in zip(bases, xs, strict=True)]
        probes = [] if step == SCREEN_STEPS else [_probe(p, i) for p in points for i in idx]
        done = runs.many(points + [q for q, _ in probes], k)
        for j, (b, p) in enumerate(zip(bases, points, strict=True)):
            obj = objective(m, done[j].curves)
            if b.choice not in best or obj < best[b.choice][1]:
                best[b.choice] = (p, obj)
            if step == SCREEN_STEPS:
                continue
            r0 = residuals(m, done[j].curves)
            first = len(points) + j * n  # this choice's probes in the batch
            jac = np.column_stack([(residuals(m, done[first + i].curves) - r0)
                                   / probes[j * n + i][1] for i in range(n)])
            dx = np.linalg.lstsq(jac, -r0, rcond=None)[0]
            size = float(np.abs(dx).max(initial=0.0))
            if size > SCREEN_TRUST:
                dx *= SCREEN_TRUST / size
            x = xs[j].copy()
            x[idx] = np.clip(x[idx] + dx, 0.0, 1.0)
            xs[j] = x
    return best


def _probe(p: Params, i: int) -> tuple[Params, float]:
    """`p` moved by STEP along scaled parameter `i` (backward at the upper bound), and the
    step."""
    x = p.scaled()
    h = STEP if x[i] + STEP <= 1.0 else -STEP
    x[i] += h
    return p.with_scaled(x), h


def search_job(d: Design, m: Measurement, lv: np.ndarray, load_kw: dict | None,
               base: Params, idx: tuple[int, ...], coarsen: int
               ) -> tuple[Params, float, Trial, int, float]:
    """The bounded least-squares search of one choice from `base` (a worker job): the best
    parameters, their objective and trial, the sweeps it ran and their CPU."""
    from scipy.optimize import least_squares

    cache: dict[Params, Trial] = {}

    def run(p: Params) -> Trial:
        if p not in cache:
            cache[p] = trial(d, p, m, lv, coarsen, load_kw)
        return cache[p]

    def full(y: np.ndarray) -> np.ndarray:
        x = base.scaled()
        x[list(idx)] = y
        return x

    res = least_squares(lambda y: residuals(m, run(base.with_scaled(full(y))).curves),
                        base.scaled()[list(idx)], bounds=(0.0, 1.0), diff_step=STEP,
                        max_nfev=MAX_EVALUATIONS, xtol=XTOL)
    fitted = base.with_scaled(full(res.x))
    t = run(fitted)
    return fitted, objective(m, t.curves), t, len(cache), sum(c.cpu_s for c in cache.values())


def at_bounds(p: Params) -> tuple[str, ...]:
    """The continuous parameters of `p` within AT_BOUND of a bound other than their nominal
    (a fit pushed there wants more than physics allows)."""
    out = []
    for k, (_lo, _hi, nom) in BOUNDS.items():
        u, n = _to_unit(k, getattr(p, k)), _to_unit(k, nom)
        if (u < AT_BOUND and n >= AT_BOUND) or (u > 1 - AT_BOUND and n <= 1 - AT_BOUND):
            out.append(k)
    return tuple(out)


def _idle(fitted: Trial, nominal: Trial) -> bool:
    """True when the border cables pull less than IDLE_SHARE of their nominal tension over the
    fitted sweep: they carry nothing (IDLE)."""
    return nominal.cable_n > 0 and fitted.cable_n < IDLE_SHARE * nominal.cable_n


def _determination(runs: Trials, p: Params, idx: list[int], k: int
                   ) -> tuple[Identifiability, dict[str, Profile]]:
    """Forward differences of the scaled residuals at `p` (backward at an upper bound), for
    every parameter, and the profiles of the free ones: one batch of sweeps."""
    m, x0 = runs.m, p.scaled()
    probes = [_probe(p, i) for i in range(len(BOUNDS))]
    grid = np.linspace(0.0, 1.0, PROFILE_POINTS)
    along = {i: [p.with_scaled(np.where(np.arange(len(x0)) == i, u, x0)) for u in grid]
             for i in idx}
    done = runs.many([p] + [q for q, _ in probes] + [q for qs in along.values() for q in qs], k)
    r0 = residuals(m, done[0].curves)
    cols, sens = [], {}
    for n, (key, (_q, h)) in enumerate(zip(BOUNDS, probes, strict=True)):
        col = (residuals(m, done[1 + n].curves) - r0) / h
        cols.append(col)
        sens[key] = float(np.linalg.norm(col))
    _, s, vt = np.linalg.svd(np.column_stack(cols), full_matrices=False)
    best = math.sqrt(objective(m, done[0].curves))
    profiles, at = {}, 1 + len(BOUNDS)
    for i, qs in along.items():
        key = list(BOUNDS)[i]
        rms = np.array([math.sqrt(objective(m, t.curves)) for t in done[at:at + len(qs)]])
        at += len(qs)
        values = np.array([getattr(q, key) for q in qs])
        near = values[rms <= best + PROFILE_RISE]
        allowed = ((float(near.min()), float(near.max())) if near.size
                   else (getattr(p, key), getattr(p, key)))
        profiles[key] = Profile(values, rms, best, bool(rms.max() > best + PROFILE_RISE),
                                allowed)
    return Identifiability(s, vt.T, sens), profiles
